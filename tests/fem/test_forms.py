"""Element-generic assembly (femkit.fem.forms) on the one pattern stack: P2 stiffness against
scikit-fem, P1 against femkit's P1 path, the compiled scatter against np.bincount, and the
block-size patterns that vector fields use."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.case.poisson import reference
from femkit.fem import assemble_stiffness, sparsity
from femkit.fem.dofs import dof_map
from femkit.fem.forms import assemble_matrix, local_matrices
from femkit.fem.mass import mass_matrix
from femkit.fem.sparsity import SparsityPattern

from ._tets import perturbed_box
from .test_mass import MESHES


@pytest.mark.parametrize("shape", sorted(MESHES))
def test_p2_stiffness_equals_scikit_fem(shape):
    mesh = MESHES[shape]()
    kappa = 1.0 + np.random.default_rng(4).random(mesh.n_cells)
    K = assemble_matrix(mesh, "stiffness", kappa, element="P2")
    ref, _ = reference.assemble(mesh, kappa, lambda *x: 0 * x[0], element="P2")
    assert abs(K - ref).max() <= 1e-12 * abs(ref).max()
    assert abs(K @ np.ones(K.shape[0])).max() <= 1e-12 * abs(ref).max()   # constants in the kernel


@pytest.mark.parametrize("shape", sorted(MESHES))
def test_generic_p1_stiffness_is_femkits_p1(shape):
    mesh = MESHES[shape]()
    kappa = 1.0 + np.random.default_rng(5).random(mesh.n_cells)
    K = assemble_matrix(mesh, "stiffness", kappa, element="P1")
    assert abs(K - assemble_stiffness(mesh, kappa)).max() <= 1e-14 * abs(K).max()


def test_compiled_scatter_equals_bincount(monkeypatch):
    mesh = perturbed_box(3)
    dofs = dof_map(mesh, "P2")
    numpy_way = assemble_matrix(mesh, "stiffness", 2.0, element="P2")
    monkeypatch.setattr(sparsity, "NUMBA_THRESHOLD", 0)
    pat = SparsityPattern.from_cells(dofs.cells, dofs.n_dofs, backend="numba")
    assert pat.slots.dtype == np.int32
    monkeypatch.setattr(sparsity, "pattern_for", lambda mesh, dofs, block=1: pat)
    compiled = assemble_matrix(mesh, "stiffness", 2.0, element="P2")
    assert abs(compiled - numpy_way).max() <= 1e-14 * abs(numpy_way).max()
    np.testing.assert_array_equal(compiled.indices, numpy_way.indices)


@pytest.mark.parametrize("block", [2, 3])
def test_block_pattern_of_a_vector_field(block):
    """Node-major blocks: the vector mass ``M (x) I_b`` summed from ``R (x) I_b`` local matrices."""
    mesh = MESHES["triangles"]()
    dofs = dof_map(mesh, "P2")
    pat = SparsityPattern.from_cells(dofs.cells, dofs.n_dofs, block=block)
    local = local_matrices(mesh, "mass", element="P2")
    eye = np.eye(block)
    vec_local = np.einsum("kij,ab->kiajb", local, eye).reshape(len(local), -1)
    M = pat.assemble(vec_local)
    expect = sp.kron(mass_matrix(mesh, element="P2"), sp.identity(block)).tocsr()
    assert M.shape == (block * dofs.n_dofs,) * 2
    assert abs(M - expect).max() <= 1e-15 and M.has_sorted_indices
    # the pattern is the block expansion of the scalar one: b^2 entries per scalar entry
    assert pat.nnz == block * block * SparsityPattern.from_cells(dofs.cells, dofs.n_dofs).nnz
