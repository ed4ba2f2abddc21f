"""The compiled P2 passes of large meshes (:mod:`femkit.fem._element_kernels`), forced on small
meshes: the row-by-row pattern gives the numpy builder's rows and slots entry for entry, the
first stiffness (summed in the pattern's row pass) the later one's (through the slots) bit for bit
and the numpy assembly's values, the compiled load (block by block) the numpy load's; a degenerate
cell or a non-finite source still raises the numpy path's one-line error."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.errors import DegenerateMeshError, InputError
from femkit.fem import forms, lagrange, quadrature, sparsity
from femkit.fem.dofs import dof_map
from femkit.mesh import Mesh, structured_box, structured_mesh


def _wobbly(mesh):
    return Mesh(mesh.points + 0.02 * np.sin(7.0 * mesh.points[:, ::-1]), mesh.cells)


def _source(dim):
    return (lambda x, y: np.sin(x) * y + x * x) if dim == 2 else (lambda x, y, z: np.sin(x) * y + z * z)


@pytest.fixture
def compiled(monkeypatch):
    monkeypatch.setattr(sparsity, "NUMBA_THRESHOLD", 0)


@pytest.mark.parametrize("mesh", [structured_mesh(5, 4), structured_box(2, 3, 2)], ids=["tri", "tet"])
def test_p2_compiled_pattern_stiffness_and_load_equal_the_numpy_paths(mesh, compiled, monkeypatch):
    monkeypatch.setattr(quadrature, "BLOCK", 7)   # the compiled load over several blocks of cells
    mesh = _wobbly(mesh)
    kappa = np.linspace(1.0, 3.0, mesh.n_cells)
    dofs = dof_map(mesh, "P2")
    K = forms.assemble_matrix(mesh, "stiffness", kappa, element="P2")   # the first: pattern and values in one pass
    assert sparsity.cached_pattern(mesh, dofs) is None                  # ... which caches no pattern
    F = lagrange.element_load(mesh, _source(mesh.dim), "P2")
    pat = sparsity.pattern_for(mesh, dofs)
    K2 = forms.assemble_matrix(mesh, "stiffness", kappa, element="P2")  # a later one: through the slots
    assert np.array_equal(K.indptr, K2.indptr) and np.array_equal(K.indices, K2.indices)
    assert np.array_equal(K.data, K2.data)                              # the same sums, bit for bit
    ref = sparsity.SparsityPattern.from_cells(dofs.cells, dofs.n_dofs, backend="numpy")
    assert np.array_equal(pat.indptr, ref.indptr) and np.array_equal(pat.indices, ref.indices)
    assert np.array_equal(pat.slots, ref.slots)
    other = Mesh(mesh.points.copy(), mesh.cells.copy())   # a new mesh: nothing cached
    monkeypatch.setattr(sparsity, "NUMBA_THRESHOLD", 10 ** 9)
    K_np = forms.assemble_matrix(other, "stiffness", kappa, element="P2")
    F_np = lagrange.element_load(other, _source(mesh.dim), "P2")
    assert abs(K - K_np).max() <= 1e-13 * abs(K_np).max()
    assert np.abs(F - F_np).max() <= 1e-14 * np.abs(F_np).max()
    assert np.isclose(F.sum(), F_np.sum(), rtol=1e-14)   # int f over the domain (the P2 partition of unity)


def test_p2_compiled_load_refuses_degenerate_cells_and_nonfinite_sources(compiled):
    mesh = structured_mesh(3, 3)
    flat = Mesh(np.where(np.arange(mesh.n_points)[:, None] == 1, mesh.points[[0]], mesh.points), mesh.cells)
    with pytest.raises(DegenerateMeshError):
        lagrange.element_load(flat, _source(2), "P2")
    with pytest.raises(InputError, match="not finite"):
        lagrange.element_load(mesh, lambda x, y: np.where(x > 0.5, np.inf, x), "P2")
