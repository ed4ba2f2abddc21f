"""The compiled setup of geometric multigrid: Galerkin triple product and transposition.

Every product is compared with SciPy's ``P.T @ A @ P`` (1e-14 relative to its largest entry, the
same pattern once SciPy's explicit zeros are gone), and the canonical form the kernel claims
(sorted, no duplicates) is checked from the arrays, not from SciPy's flags (which the kernel sets).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.fem import apply_dirichlet, assemble_stiffness
from femkit.mesh import Mesh, MeshHierarchy, boundary_nodes, generate
from femkit.solvers.gmg import Multigrid, galerkin_product, transpose_csr

SQUARE = Mesh(points=[[0, 0], [1, 0], [1, 1], [0, 1]], triangles=[[0, 1, 2], [0, 2, 3]])


def _reference(A, P) -> sp.csr_matrix:
    R = (P.T @ A @ P).tocsr()
    R.eliminate_zeros()
    R.sort_indices()
    return R


def _assert_canonical(C: sp.csr_matrix) -> None:
    assert C.indptr[0] == 0 and C.indptr[-1] == C.nnz == len(C.indices) == len(C.data)
    assert np.all(np.diff(C.indptr) >= 0)
    for i in range(C.shape[0]):
        row = C.indices[C.indptr[i]:C.indptr[i + 1]]
        assert np.all(np.diff(row) > 0), f"row {i} not strictly increasing: {row}"
    assert np.all(C.data != 0.0)       # exact zeros dropped, as SciPy's product drops them


def _assert_matches_scipy(A, P, C, diag) -> None:
    R = _reference(A, P)
    _assert_canonical(C)
    assert C.shape == R.shape
    np.testing.assert_array_equal(C.indptr, R.indptr)
    np.testing.assert_array_equal(C.indices, R.indices)
    scale = max(abs(R).max(), 1e-300) if R.nnz else 1.0
    assert np.abs(C.data - R.data).max(initial=0.0) <= 1e-14 * scale
    assert np.abs(diag - R.diagonal()).max(initial=0.0) <= 1e-14 * scale


def _random_spd(n: int, rng, density: float = 0.05) -> sp.csr_matrix:
    B = sp.random(n, n, density=density, random_state=rng, format="csr")
    return (B @ B.T + sp.identity(n)).tocsr()


def _random_prolongation(n_fine: int, n_coarse: int, rng, max_per_row: int = 3) -> sp.csr_matrix:
    """A CSR ``P`` with 0 .. max_per_row entries per row, in unsorted column order."""
    rows, cols = [], []
    for i in range(n_fine):
        k = rng.integers(0, max_per_row + 1)
        c = rng.choice(n_coarse, size=min(k, n_coarse), replace=False)
        rows += [i] * len(c)
        cols += list(c)
    vals = rng.uniform(0.1, 1.0, size=len(rows))
    P = sp.csr_matrix((vals, (rows, cols)), shape=(n_fine, n_coarse))
    perm = [rng.permutation(np.arange(P.indptr[i], P.indptr[i + 1])) for i in range(n_fine)]
    order = np.concatenate(perm) if perm else np.zeros(0, dtype=int)
    return sp.csr_matrix((P.data[order], P.indices[order], P.indptr), shape=P.shape)


def _hierarchy_case(dirichlet: bool):
    H = MeshHierarchy.from_refinement(generate("l_shape", 0.5), 3, renumber="rcm")
    K = assemble_stiffness(H.finest, 1.0)
    if dirichlet:
        sys = apply_dirichlet(K, np.ones(H.finest.n_points), boundary_nodes(H.finest), 0.0)
        A, free = sys.A, sys.free
    else:
        A, free = K.tocsr(), np.arange(H.finest.n_points)
    frees = H.level_free(free)
    return A, H.free_prolongations(frees[-1])[-1]


def _case(name: str):
    rng = np.random.default_rng(7)
    if name == "random":
        return _random_spd(200, rng), _random_prolongation(200, 60, rng)
    if name == "random-nonsymmetric":
        A = sp.random(150, 150, density=0.06, random_state=rng, format="csr") + sp.identity(150)
        return A.tocsr(), _random_prolongation(150, 40, rng)
    if name == "int64-indices":
        A, P = _random_spd(120, rng), _random_prolongation(120, 30, rng)
        for M in (A, P):
            M.indices, M.indptr = M.indices.astype(np.int64), M.indptr.astype(np.int64)
        return A, P
    if name == "dense-coarse":      # C much denser than A: the output outgrows its first buffer
        return sp.identity(80, format="csr") * 2.0, _random_prolongation(80, 50, rng, 12)
    if name == "duplicates-in-A":   # not canonical: duplicates are summed
        return _duplicated(_random_spd(60, rng)), _random_prolongation(60, 20, rng)
    if name == "hierarchy":
        return _hierarchy_case(dirichlet=False)
    if name == "with-dirichlet":
        return _hierarchy_case(dirichlet=True)
    raise AssertionError(name)


def _duplicated(A: sp.csr_matrix) -> sp.csr_matrix:
    """``A`` with every entry split in two halves stored twice in its row (not canonical)."""
    n = A.shape[0]
    counts = np.diff(A.indptr)
    indptr = np.concatenate([[0], np.cumsum(2 * counts)])
    indices = np.empty(2 * A.nnz, dtype=A.indices.dtype)
    data = np.empty(2 * A.nnz)
    for i in range(n):
        a, b = A.indptr[i], A.indptr[i + 1]
        s = indptr[i]
        indices[s:s + 2 * (b - a)] = np.concatenate([A.indices[a:b][::-1], A.indices[a:b]])
        data[s:s + 2 * (b - a)] = np.concatenate([A.data[a:b][::-1], A.data[a:b]]) / 2
    D = sp.csr_matrix((data, indices, indptr), shape=A.shape)
    assert not D.has_canonical_format
    return D


CASES = ["random", "random-nonsymmetric", "int64-indices", "dense-coarse", "duplicates-in-A",
         "hierarchy", "with-dirichlet"]


@pytest.mark.parametrize("name", CASES)
def test_galerkin_product_equals_scipy(name):
    A, P = _case(name)
    C, diag = galerkin_product(A, P)
    _assert_matches_scipy(A, P, C, diag)


@pytest.mark.parametrize("name", CASES)
def test_transpose_equals_scipy_array_for_array(name):
    _, P = _case(name)
    T, R = transpose_csr(P), P.T.tocsr()
    assert T.shape == R.shape
    for a, b in ((T.indptr, R.indptr), (T.indices, R.indices), (T.data, R.data)):
        np.testing.assert_array_equal(a, b)


def test_empty_rows_and_columns():
    rng = np.random.default_rng(3)
    A = _random_spd(40, rng).tolil()
    A[5, :] = 0.0                                  # an empty row of A
    A = A.tocsr()
    A.eliminate_zeros()
    P = _random_prolongation(40, 12, rng).tolil()
    P[:, 4] = 0.0                                  # coarse dof 4 unused: empty row and column of C
    P[7, :] = 0.0                                  # a fine dof without coarse parents
    P = P.tocsr()
    P.eliminate_zeros()
    C, diag = galerkin_product(A, P)
    _assert_matches_scipy(A, P, C, diag)
    assert C.indptr[5] == C.indptr[4] and 4 not in C.indices and diag[4] == 0.0


def test_one_by_one_and_empty_coarse_levels():
    rng = np.random.default_rng(5)
    A = _random_spd(30, rng)
    P = sp.csr_matrix(rng.uniform(0.1, 1.0, size=(30, 1)))
    C, diag = galerkin_product(A, P)
    _assert_matches_scipy(A, P, C, diag)
    assert C.shape == (1, 1) and C.nnz == 1
    assert diag[0] == pytest.approx(float(P.toarray()[:, 0] @ A @ P.toarray()[:, 0]), rel=1e-14)
    C0, d0 = galerkin_product(A, sp.csr_matrix((30, 0)))
    assert C0.shape == (0, 0) and C0.nnz == 0 and d0.shape == (0,)


def test_exact_cancellation_is_dropped_like_scipy():
    A = sp.csr_matrix(np.array([[1.0, -1.0], [-1.0, 1.0]]))
    P = sp.csr_matrix(np.array([[1.0], [1.0]]))    # the constant: in A's kernel
    C, diag = galerkin_product(A, P)
    assert C.shape == (1, 1) and C.nnz == 0 and diag[0] == 0.0
    assert _reference(A, P).nnz == 0


def test_mismatched_shapes_are_input_errors():
    from femkit.errors import InputError

    A = sp.identity(4, format="csr")
    with pytest.raises(InputError, match="rows"):
        galerkin_product(A, sp.csr_matrix((5, 2)))
    with pytest.raises(InputError, match="P\\^T"):
        galerkin_product(A, sp.csr_matrix((4, 2)), PT=sp.csr_matrix((4, 2)))


def test_multigrid_levels_are_scipy_galerkin_products_down_to_a_1x1_level():
    # the two-triangle square: all 4 coarse nodes are on the boundary (level 0 has no unknowns),
    # level 1 has one interior node (a 1 x 1 operator)
    H = MeshHierarchy.from_refinement(SQUARE, 4, renumber="rcm")
    sys = apply_dirichlet(assemble_stiffness(H.finest), np.ones(H.finest.n_points),
                          boundary_nodes(H.finest), 0.0)
    mg = Multigrid(sys.A, H, free=sys.free)
    assert mg.info["sizes"][:2] == [0, 1]
    for lvl in range(mg.n_levels - 1):
        P, R = mg.prolongations[lvl], mg.restrictions[lvl]
        assert (R != P.T).nnz == 0                 # the restriction is the transpose, reused
        fine = mg.levels[lvl + 1].A
        C = mg.levels[lvl].A
        _assert_matches_scipy(fine, P, C, C.diagonal())
        np.testing.assert_allclose(mg.levels[lvl].inv_diag, mg.omega / C.diagonal(), rtol=1e-15)
    x = mg.vcycle(np.ones(sys.A.shape[0]))
    assert np.all(np.isfinite(x)) and x @ np.ones(sys.A.shape[0]) > 0


@pytest.mark.parametrize("name", ["dense-coarse", "hierarchy"])
@pytest.mark.parametrize("capacity", [1, 7, 10 ** 6], ids=["cap1", "cap7", "cap1e6"])
def test_galerkin_output_growth_is_invisible(name, capacity):
    """The compiled pass stops at a row that does not fit and the buffers grow between calls:
    whatever the starting capacity, the same arrays (and rows longer than 32 entries, sorted by
    the Shell sort, in canonical order as SciPy's)."""
    from femkit.solvers import _gmg_kernels
    from femkit.solvers.gmg import _kernel_index

    A, P = _case(name)
    A, P = A.tocsr(), P.tocsr()
    PT = transpose_csr(P)
    args = [a for M in (PT, A, P) for a in (_kernel_index(M.indptr), _kernel_index(M.indices),
                                              M.data)]
    ref = _gmg_kernels.galerkin(*args, A.nnz * 4)
    got = _gmg_kernels.galerkin(*args, capacity)
    for a, b in zip(got, ref):
        np.testing.assert_array_equal(a, b)
    C, diag = galerkin_product(A, P)
    _assert_matches_scipy(A, P, C, diag)
    if name == "dense-coarse":
        assert np.diff(C.indptr).max() > 32
