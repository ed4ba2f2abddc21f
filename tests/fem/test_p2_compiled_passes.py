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


@pytest.mark.parametrize("dim, p2_cells", [(2, 50_000), (3, 32_000)], ids=["tri", "tet"])
def test_p2_takes_the_compiled_passes_from_as_many_local_entries_as_p1(dim, p2_cells):
    """P2 goes compiled from NUMBA_THRESHOLD * (P1 local entries) / (P2 local entries) cells (a
    quarter of P1's cells in 2D, 16 % in 3D); P1 keeps its own threshold exactly."""
    from femkit.elements import get_element

    p1, p2 = get_element("P1", dim), get_element("P2", dim)
    assert sparsity.compiled_from(sparsity.NUMBA_THRESHOLD, p1)
    assert not sparsity.compiled_from(sparsity.NUMBA_THRESHOLD - 1, p1)
    assert sparsity.compiled_from(p2_cells, p2) and not sparsity.compiled_from(p2_cells - 1, p2)


def test_a_p2_mesh_between_the_two_thresholds_is_assembled_compiled(monkeypatch):
    monkeypatch.setattr(sparsity, "NUMBA_THRESHOLD", 100)   # P2 triangles compiled from 25 on
    mesh = _wobbly(structured_mesh(4, 4))                    # 32 cells: P1 would stay on numpy
    from femkit.fem import _element_kernels

    calls = []
    real = _element_kernels.first_stiffness
    monkeypatch.setattr(_element_kernels, "first_stiffness", lambda *a: calls.append(1) or real(*a))
    K = forms.assemble_matrix(mesh, "stiffness", 1.0, element="P2")
    assert calls == [1]
    monkeypatch.setattr(sparsity, "NUMBA_THRESHOLD", 10 ** 9)
    K_np = forms.assemble_matrix(Mesh(mesh.points.copy(), mesh.cells.copy()), "stiffness", 1.0, element="P2")
    assert abs(K - K_np).max() <= 1e-13 * abs(K_np).max()


@pytest.mark.parametrize("dim", [2, 3], ids=["tri", "tet"])
def test_p2_compiled_stiffness_from_the_cell_metric_equals_scikit_fem_and_is_exactly_symmetric(dim, compiled):
    """The compiled stiffness sums each cell's metric (vertices 1..d) against the reference tensor
    folded for it (:func:`femkit.fem._element_kernels.metric_table`), not the quadrature of the
    gradients: on randomly distorted cells with a random kappa it is scikit-fem's ElementTriP2 /
    ElementTetP2 stiffness to 1e-12, first call (row pass) and later call (slots) alike, and
    exactly symmetric."""
    from femkit.case.poisson import reference

    from ._tets import perturbed_box

    if dim == 2:
        base = structured_mesh(7, 6)
        rng = np.random.default_rng(11)
        p = base.points.copy()
        inner = ((p > 1e-12) & (p < 1 - 1e-12)).all(axis=1)
        p[inner] += 0.35 / 7 * rng.uniform(-0.5, 0.5, (int(inner.sum()), 2))
        mesh = Mesh(p, base.cells)
    else:
        mesh = perturbed_box(3, amount=0.35)
    kappa = 0.5 + np.random.default_rng(2).random(mesh.n_cells)
    K_ref, _ = reference.assemble(mesh, kappa, lambda *x: x[0], element="P2")
    first = forms.assemble_matrix(mesh, "stiffness", kappa, element="P2")
    later = forms.assemble_matrix(mesh, "stiffness", kappa, element="P2")
    for K in (first, later):
        assert abs(K - K_ref).max() <= 1e-12 * abs(K_ref).max()
        assert (K != K.T).nnz == 0
