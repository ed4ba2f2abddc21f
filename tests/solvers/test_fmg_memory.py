"""What fmg holds: the transfers without copies, the Dirichlet data through the prolongations'
fixed columns, a bounded set of work vectors, a constant coefficient as one number.

Every saving must leave the numbers as they were: the split prolongation equals the full
product bit for bit, the CSC restriction equals the CSR transpose's product bit for bit, and a
constant coefficient given as a number gives the same assembly, solution and estimate as the same
constant per cell.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.errors import InputError
from femkit.fem import apply_dirichlet, assemble_load, assemble_stiffness
from femkit.mesh import Mesh, MeshHierarchy, boundary_nodes, generate, structured_box
from femkit.mesh.hierarchy import _fixed_columns
from femkit.solvers.fmg import fmg
from femkit.solvers.gmg import Multigrid, transpose_csr

SQUARE = Mesh(points=[[0, 0], [1, 0], [1, 1], [0, 1]], triangles=[[0, 1, 2], [0, 2, 3]])


def _hierarchy(kind: str) -> MeshHierarchy:
    if kind == "triangles":
        return MeshHierarchy.from_refinement(SQUARE, 4)
    if kind == "triangles-rcm":
        return MeshHierarchy.from_refinement(generate("l_shape", 0.3), 3, renumber="rcm")
    return MeshHierarchy.from_refinement(structured_box(1, 1, 1), 2, renumber="rcm")


def _free(H: MeshHierarchy, which: str) -> np.ndarray:
    n = H.finest.n_points
    fixed = boundary_nodes(H.finest)
    if which == "random":  # fixed nodes anywhere, also inside: rows with two fixed parents
        fixed = np.union1d(fixed[::2], np.random.default_rng(3).choice(n, n // 5, replace=False))
    return np.setdiff1d(np.arange(n), fixed)


KINDS = ["triangles", "triangles-rcm", "tetrahedra-rcm"]


@pytest.mark.parametrize("which", ["boundary", "random"], ids=["boundary-fixed", "random-fixed"])
@pytest.mark.parametrize("kind", KINDS)
def test_free_and_fixed_prolongations_split_the_full_product_bit_for_bit(kind, which):
    H = _hierarchy(kind)
    free = _free(H, which)
    frees = H.level_free(free)
    rng = np.random.default_rng(1)
    for lvl, ((Pd, fixed), Pf) in enumerate(zip(H.fixed_prolongations(free),
                                                 H.free_prolongations(free))):
        u = rng.standard_normal(H.prolongations[lvl].shape[1])
        np.testing.assert_array_equal(np.flatnonzero(~np.isin(np.arange(len(u)), frees[lvl])),
                                      fixed)
        full = H.prolongate(u, lvl)[frees[lvl + 1]]
        split = Pf @ u[frees[lvl]] + Pd @ u[fixed]
        assert np.array_equal(split, full)                   # the same sums, not only close
        # and the very matrix SciPy's fancy indexing gives, entries in their order
        ref = H.prolongations[lvl][frees[lvl + 1]][:, fixed].tocsr()
        for got, want in ((Pd.indptr, ref.indptr), (Pd.indices, ref.indices), (Pd.data, ref.data)):
            np.testing.assert_array_equal(got, want)
    # the free ids of every level, when already known, give the same parts
    for (a, fa), (b, fb) in zip(H.fixed_prolongations(free), H.fixed_prolongations(frees=frees)):
        assert (a != b).nnz == 0 and np.array_equal(fa, fb)


def test_fixed_columns_of_rows_without_fixed_entries_are_empty():
    P = sp.csr_matrix(np.array([[1.0, 0, 0], [0.5, 0.5, 0], [0, 0.5, 0.5], [0, 0, 1]]))
    D = _fixed_columns(P, np.array([0, 3]), np.array([False, True, False]))
    assert D.shape == (2, 1) and D.nnz == 0
    D = _fixed_columns(P, np.array([], dtype=np.int64), np.array([True, True, True]))
    assert D.shape == (0, 3) and D.nnz == 0


@pytest.mark.parametrize("kind", KINDS)
def test_restriction_is_the_prolongation_read_as_csc_with_the_transposes_sums(kind):
    H = _hierarchy(kind)
    m = H.finest
    sys_ = apply_dirichlet(assemble_stiffness(m), np.ones(m.n_points), boundary_nodes(m), 0.0)
    mg = Multigrid(sys_.A, H, free=sys_.free)
    rng = np.random.default_rng(0)
    for P, R in zip(mg.prolongations, mg.restrictions):
        if P.nnz:                                            # a view: no second copy held
            assert np.shares_memory(R.data, P.data) and np.shares_memory(R.indices, P.indices)
        r = rng.standard_normal(P.shape[0])
        assert np.array_equal(R @ r, transpose_csr(P) @ r)
    assert mg.levels[-1].x is None                           # the cycle's output is new anyway
    assert all(L.x is not None for L in mg.levels[1:-1])
    for lvl, L in enumerate(mg.levels):                      # A v in the work vector: SciPy's sums
        v = rng.standard_normal(L.A.shape[0])
        out = mg.matvec(v, lvl)
        assert out is L.r and np.array_equal(out, L.A @ v)


def test_level_free_reuses_increasing_finest_ids_and_sorts_any_other():
    H = _hierarchy("triangles")
    free = _free(H, "boundary")
    assert H.level_free(free)[-1] is free
    shuffled = np.random.default_rng(0).permutation(free)
    got = H.level_free(shuffled)
    assert got[-1] is not shuffled and np.array_equal(got[-1], free)
    for a, b in zip(got, H.level_free(free)):
        np.testing.assert_array_equal(a, b)


def test_hierarchy_without_coarse_meshes_keeps_every_transfer():
    H = _hierarchy("triangles-rcm")
    lean = H.without_coarse_meshes()
    assert lean.n_levels == H.n_levels and lean.finest is H.finest
    assert all(m is None for m in lean.meshes[:-1])
    free = _free(H, "boundary")
    for a, b in zip(lean.free_prolongations(free), H.free_prolongations(free)):
        assert (a != b).nnz == 0
    assert repr(lean) == repr(H)


def _square_system(g):
    H = MeshHierarchy.from_refinement(generate("unit_square", 0.1), 4)
    m = H.finest
    K, F = assemble_stiffness(m), assemble_load(m, 1.0)
    nodes = boundary_nodes(m)
    return H, apply_dirichlet(K, F, nodes, g(*m.points[nodes].T)), m


@pytest.mark.parametrize("data", ["zero", "inhomogeneous"])
def test_fmg_holds_less_than_a_few_matrices(data):
    """NumPy's allocations during an fmg solve (tracemalloc; the compiled Galerkin pass's own
    buffers are not traced) against the bytes of the finest matrix: the work vectors, the
    transfers and the coarse data. Before the restriction became a view, the Dirichlet values a
    split product, the start and the finest right-hand side formed when needed and the loop's
    vectors released in time, this was 3.8x (zero data) and 5.3x (inhomogeneous) the matrix on
    a 30,657-unknown square (refined 4 times), 1.6x and 3.1x after."""
    g = (lambda x, y: 0 * x) if data == "zero" else (lambda x, y: 1 + x * y)
    H, sys_, m = _square_system(g)
    kw = {} if data == "zero" else {"dirichlet": sys_.expand(np.zeros(len(sys_.free)))}
    fmg(sys_.A, sys_.b, hierarchy=H, free=sys_.free, **kw)  # compiled, cached
    A = sys_.A
    matrix = A.data.nbytes + A.indices.nbytes + A.indptr.nbytes
    tracemalloc.start()
    try:
        res = fmg(sys_.A, sys_.b, hierarchy=H, free=sys_.free, **kw)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert res.converged
    assert peak <= (2.5 if data == "zero" else 4.0) * matrix, peak / matrix


def test_constant_coefficient_as_one_number_changes_no_result(tmp_path):
    """The pipeline keeps a number coefficient as one float (no per-cell array); the same
    constant as an expression (evaluated per cell) gives the same numbers bit for bit, and the
    VTU still carries one value per cell."""
    import meshio

    from femkit.case import case_from_dict

    runs = {}
    for name, coef in (("number", 2.5), ("expression", "2.5 + 0 * x")):
        case = case_from_dict({
            "problem": "poisson", "name": name,
            "mesh": {"geometry": "unit_square", "h": 0.2, "refine": 2},
            "coefficient": coef, "source": "1 + x * y",
            "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "x - y"}]},
            "exact": {"u": "x - y", "grad": ["1 + 0 * x", "-1 + 0 * y"]},
            "estimator": "residual", "solver": {"method": "fmg"},
            "output": {"dir": str(tmp_path / name), "vtu": True, "plot": False}})
        runs[name] = case.run(quiet=True)
    num, expr = runs["number"], runs["expression"]
    assert isinstance(num.kappa, float) and np.shape(expr.kappa) == (num.mesh.n_cells,)
    assert np.array_equal(num.u, expr.u)
    assert num.errors == expr.errors
    assert num.error_estimate == expr.error_estimate
    cells = meshio.read(tmp_path / "number" / "solution.vtu").cell_data["kappa"][0]
    np.testing.assert_array_equal(cells, np.full(num.mesh.n_cells, 2.5))


def _levels(H, g):
    """The coarser levels' own systems (what the case pipeline passes fmg as ``levels``)."""
    out = []
    for m in H.meshes[:-1]:
        nodes = boundary_nodes(m)
        out.append(apply_dirichlet(assemble_stiffness(m), assemble_load(m, 1.0), nodes,
                                   g(*m.points[nodes].T)))
    return out


@pytest.mark.parametrize("which", ["boundary", "random"], ids=["boundary-fixed", "random-fixed"])
@pytest.mark.parametrize("kind", KINDS)
def test_free_node_hierarchy_holds_the_same_transfers_without_the_full_ones(kind, which):
    """``on_free_nodes`` restricts once and keeps the restricted matrices only: the same
    free-node lists and matrices, the fixed-column parts as CSC with CSR's products bit for bit."""
    H = _hierarchy(kind)
    free = _free(H, which)
    F = H.on_free_nodes(free)
    assert not hasattr(F, "prolongations") and F.n_levels == H.n_levels and F.finest is H.finest
    for a, b in zip(F.level_free(free), H.level_free(free)):
        np.testing.assert_array_equal(a, b)
    for a, b in zip(F.free_prolongations(free), H.free_prolongations(free)):
        for name in ("indptr", "indices", "data"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    rng = np.random.default_rng(2)
    for (a, fa), (b, fb) in zip(F.fixed_prolongations(frees=F.frees), H.fixed_prolongations(free)):
        assert a.format == "csc" and (a != b).nnz == 0 and np.array_equal(fa, fb)
        g = rng.standard_normal(len(fb))
        assert np.array_equal(a @ g, b @ g)               # the same sums
    # a mask of the same nodes is the same set; fixed parts not built are refused by name
    assert F.level_free(np.isin(np.arange(H.finest.n_points), free))[-1] is F.frees[-1]
    with pytest.raises(InputError, match="fixed_parts=False"):
        H.on_free_nodes(free, fixed_parts=False).fixed_prolongations(free)


def test_free_node_hierarchy_refuses_other_free_nodes():
    H = _hierarchy("triangles")
    free = _free(H, "boundary")
    F = H.on_free_nodes(free)
    for other in (free[1:], _free(H, "random")):
        for call in (F.level_free, F.free_prolongations, F.fixed_prolongations):
            with pytest.raises(InputError, match="other free nodes"):
                call(other)
    with pytest.raises(InputError, match="out of range"):
        F.level_free([H.finest.n_points])


@pytest.mark.parametrize("coarse", ["levels", "dirichlet", "restricted"])
def test_fmg_and_gmg_on_the_free_node_hierarchy_give_the_same_numbers(coarse):
    g = lambda x, y: 1 + x * y  # noqa: E731  inhomogeneous: the fixed-column parts are used
    H, sys_, m = _square_system(g)
    kw = {"levels": {"levels": _levels(H, g)},
          "dirichlet": {"dirichlet": sys_.expand(np.zeros(len(sys_.free)))},
          "restricted": {}}[coarse]
    F = H.on_free_nodes(sys_.free, fixed_parts=coarse != "restricted")
    full = fmg(sys_.A, sys_.b, hierarchy=H, free=sys_.free, **kw)
    lean = fmg(sys_.A, sys_.b, hierarchy=F, free=sys_.free, **kw)
    assert np.array_equal(full.x, lean.x) and np.array_equal(full.residuals, lean.residuals)
    assert full.info["discretisation_error_estimate"] == lean.info["discretisation_error_estimate"]
    from femkit.solvers import pcg
    from femkit.solvers.gmg import build

    a, b = (pcg(sys_.A, sys_.b, M=build(sys_.A, hierarchy=h, free=sys_.free), rtol=1e-10)
            for h in (H, F))
    assert np.array_equal(a.x, b.x)


def test_the_run_releases_the_full_prolongations_before_the_solve(tmp_path, monkeypatch):
    """The case pipeline restricts its hierarchy's transfers at the start of the solve and
    keeps the restricted ones only: no full prolongation is alive when the multigrid set-up
    starts (61 MiB at 1.9M fine nodes, held through the solve before). The numbers are those of
    a solve given the full hierarchy."""
    import weakref

    from femkit.case import case_from_dict
    import femkit.case.poisson.run as run_module
    import femkit.solvers.gmg as gmg_module

    made, alive = [], []
    refine = MeshHierarchy.from_refinement.__func__

    def recording(cls, *args, **kwargs):
        H = refine(cls, *args, **kwargs)
        made.append([weakref.ref(P) for P in H.prolongations])
        return H

    init = gmg_module.Multigrid.__init__

    def counting(self, *args, **kwargs):
        alive.append(sum(ref() is not None for ref in made[-1]))
        init(self, *args, **kwargs)

    monkeypatch.setattr(MeshHierarchy, "from_refinement", classmethod(recording))
    monkeypatch.setattr(gmg_module.Multigrid, "__init__", counting)
    runs = []
    for name in ("lean", "full"):
        if name == "full":  # the solver given the whole hierarchy, as before
            monkeypatch.setattr(run_module, "on_free_nodes", lambda overrides: overrides)
        case = case_from_dict({
            "problem": "poisson", "name": name,
            "mesh": {"geometry": "unit_square", "h": 0.2, "refine": 3},
            "coefficient": 1.0, "source": "1 + x * y",
            "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "1 + x * y"}]},
            "exact": {"u": "1 + x * y", "grad": ["y", "x"]},
            "estimator": "residual", "solver": {"method": "fmg"},
            "output": {"dir": str(tmp_path / name), "vtu": False, "plot": False}})
        runs.append(case.run(quiet=True, write=False))
    assert alive == [0, len(made[-1])] and len(made[-1]) == 3
    lean, full = runs
    assert np.array_equal(lean.u, full.u)
    assert lean.errors == full.errors and lean.error_estimate == full.error_estimate
    assert lean.solve.info["discretisation_error_estimate"] == \
        full.solve.info["discretisation_error_estimate"]

