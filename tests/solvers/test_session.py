"""The linear-solve session: what it reuses over a sequence of solves (orderings, symbolic
analyses, kept factors as preconditioners), that every answer meets the spec's stopping rule,
and that its matrix-free rule is the registry's own declaration (one table)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import aslinearoperator, spsolve

from femkit.errors import InputError, SolverError
from femkit.solvers import SOLVERS, SolverSpec
from femkit.solvers.registry import declare, traits
from femkit.solvers.session import LinearSession, check_matrix_free, matrix_free_message

from .conftest import poisson_2d


def _family(m=10, k=4):
    """``k`` SPD matrices of one pattern with different values (a matrix refactorised per step)."""
    A = poisson_2d(m)
    return [(A + (1.0 + j) * sp.identity(A.shape[0])).tocsr() for j in range(k)]


def _rhs(n):
    return np.cos(np.arange(n, dtype=float))


def _residual_ok(A, x, b, rtol):
    return np.linalg.norm(b - A @ x) <= rtol * np.linalg.norm(b)


def test_direct_refactor_orders_once_per_pattern_and_answers_each_matrix():
    s = SolverSpec("direct").session()
    mats = _family()
    b = _rhs(mats[0].shape[0])
    for A in mats:
        x = s.solve(A, b, refactor=True)
        np.testing.assert_allclose(x, spsolve(A.tocsc(), b), rtol=1e-10)
    assert s.stats["orderings"] == 1 and s.stats["factorizations"] == len(mats)
    other = poisson_2d(9).tocsr()                       # a new pattern is ordered afresh
    s.solve(other, _rhs(81), refactor=True)
    assert s.stats["orderings"] == 2


def test_a_kept_factor_preconditions_later_solves_to_the_spec_tolerance():
    spec = SolverSpec("direct", rtol=1e-10)
    s = spec.session()
    mats = _family(k=5)
    b = _rhs(mats[0].shape[0])
    for A in mats:
        x = s.solve(A, b, refactor=True, keep="k")
        assert _residual_ok(A, x, b, spec.rtol)
    assert s.stats["factorizations"] < len(mats)      # some solves were PCG with the kept factor
    assert s.stats["linear_iterations"] > 0


@pytest.mark.cholmod
def test_solve_on_pattern_refactorises_on_one_symbolic_analysis():
    class Pattern:                                     # one group: every entry always factorised
        n_groups = 1
        kept_groups = np.array([0])

        def __init__(self, A):
            self.entry_group = np.zeros(A.nnz, dtype=np.int8)

    mats = _family(k=4)
    pat = Pattern(mats[0])
    s = SolverSpec("cholesky").session()
    b = _rhs(mats[0].shape[0])
    for A in mats:
        x = s.solve_on_pattern(A, b, pat)
        assert _residual_ok(A, x, b, s.spec.rtol)
    assert s.stats["factorizations"] == 4 and s.stats["symbolic_reuses"] >= 3


def test_factorize_keeps_one_factor_for_block_solves():
    A = poisson_2d(8)
    s = SolverSpec("direct").session()
    F = s.factorize(A)
    B = np.random.default_rng(1).standard_normal((A.shape[0], 2))
    np.testing.assert_allclose(A @ F.solve(B), B, atol=1e-11)
    assert s.stats["factorizations"] == 1


def test_a_zero_right_hand_side_gives_zero_without_factorising():
    s = SolverSpec("direct").session()
    x = s.solve(poisson_2d(5).tocsr(), np.zeros(25), refactor=True)
    assert not x.any() and s.stats.get("factorizations", 0) == 0


def test_an_unconverged_iterative_solve_is_a_solver_error():
    s = SolverSpec("cg", maxiter=2).session()
    with pytest.raises(SolverError, match="did not converge"):
        s.solve(poisson_2d(10), _rhs(100))


def test_matrix_free_solves_use_the_diagonal_for_jacobi():
    A = poisson_2d(8)
    b = _rhs(64)
    s = SolverSpec("pcg", "jacobi").session()
    x = s.solve(aslinearoperator(A), b, diagonal=A.diagonal())
    assert _residual_ok(A, x, b, s.spec.rtol)
    with pytest.raises(InputError, match="needs the operator's diagonal"):
        s.solve(aslinearoperator(A), b)


@pytest.mark.parametrize("spec", [SolverSpec("direct"), SolverSpec("jacobi"),
                                  SolverSpec("pcg", "ic0")], ids=["direct", "jacobi", "pcg+ic0"])
def test_matrix_free_refuses_solvers_that_need_the_matrix(spec):
    with pytest.raises(InputError, match=r"matrix-free needs an iterative solver: cg or pcg \(jacobi\)"):
        spec.session().solve(aslinearoperator(poisson_2d(4)), np.ones(16))


def test_keeping_a_factor_needs_femkit_s_backend():
    s = SolverSpec.from_mapping({"method": "direct", "backend": "petsc"}).session()
    with pytest.raises(InputError, match="backend 'petsc' is not supported"):
        s.solve(poisson_2d(4).tocsr(), np.ones(16), refactor=True, keep="k")


@pytest.fixture
def registered_solver():
    """A new matrix-free method registered for the test only (plain CG under another name)."""
    from femkit.solvers.cg import cg

    def newcomer(A, b, x0=None, **kw):
        return cg(A, b, x0, **kw)

    SOLVERS.register("newcomer", declare(newcomer, matrix_free=True))
    yield "newcomer"
    SOLVERS.remove("newcomer")


def test_the_matrix_free_rule_is_what_the_registry_entries_declare(registered_solver):
    assert traits(SOLVERS, registered_solver).matrix_free
    assert "newcomer" in matrix_free_message()
    spec = SolverSpec(registered_solver)
    check_matrix_free("implicit_euler", spec)          # accepted with no list edited
    A = poisson_2d(6)
    x = LinearSession(spec).solve(aslinearoperator(A), _rhs(36))
    assert _residual_ok(A, x, _rhs(36), spec.rtol)


@pytest.mark.parametrize("case", ["poisson", "random-unsorted", "one-row"])
def test_symmetric_permutation_is_scipys_fancy_indexing(case):
    """The refactorisation's permuted matrix: the same CSC arrays (what SuperLU reads) as
    ``A[perm][:, perm]``, for sorted and unsorted rows."""
    from femkit.solvers.session import symmetric_permutation

    rng = np.random.default_rng(3)
    if case == "poisson":
        A = poisson_2d(9)
    elif case == "one-row":
        A = sp.csr_matrix(np.array([[2.5]]))
    else:
        A = sp.random(60, 60, density=0.1, random_state=4, format="csr")
        A = (A + A.T + sp.identity(60)).tocsr()
        for r in range(60):   # reverse each row's stored order
            lo, hi = A.indptr[r], A.indptr[r + 1]
            A.indices[lo:hi], A.data[lo:hi] = A.indices[lo:hi][::-1].copy(), A.data[lo:hi][::-1].copy()
        A.has_sorted_indices = False
    perm = rng.permutation(A.shape[0])
    ours, theirs = symmetric_permutation(A, perm).tocsc(), A[perm][:, perm].tocsc()
    for a in (ours, theirs):
        a.sum_duplicates()
    np.testing.assert_array_equal(ours.indptr, theirs.indptr)
    np.testing.assert_array_equal(ours.indices, theirs.indices)
    np.testing.assert_array_equal(ours.data, theirs.data)


def test_refactorised_steps_are_bit_identical_to_fancy_indexing(monkeypatch):
    """An implicit run over many steps (ordering reused every step): the same trajectory, bit
    for bit, as with SciPy's fancy indexing."""
    import warnings

    import femkit.solvers.session as session
    from femkit.dynamics.simulate import simulate
    from femkit.dynamics.topology import cloth_grid

    from femkit.dynamics.forces.gravity import Gravity

    system = cloth_grid(5, 4, 1.0, 1.0, k_structural=200.0, total_mass=0.2, pinned="top_corners",
                        forces=[Gravity(9.81)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ours = simulate(system, "implicit_euler", 0.01, 0.2)
        monkeypatch.setattr(session, "symmetric_permutation", lambda A, p: A[p][:, p])
        theirs = simulate(system, "implicit_euler", 0.01, 0.2)
    assert ours.stats["orderings"] < ours.stats["factorizations"] and ours.stats["time_permute"] > 0
    np.testing.assert_array_equal(ours.x, theirs.x)
    np.testing.assert_array_equal(ours.v, theirs.v)


def _stiff_pairs(K: float, n: int = 40):
    """An SPD matrix like a stiff barrier's Newton matrix: node pairs held by stiffness ``K``,
    soft springs (1) between the pairs, a small mass (1e-3) on the diagonal."""
    rows, cols, vals = [np.arange(n)], [np.arange(n)], [np.full(n, 1e-3)]
    for first, k in ((0, K), (1, 1.0)):
        i = np.arange(first, n - 1, 2)
        rows += [i, i + 1, i, i + 1]
        cols += [i, i + 1, i + 1, i]
        vals += [np.full(len(i), k), np.full(len(i), k), np.full(len(i), -k), np.full(len(i), -k)]
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n, n))


def test_a_direct_answer_that_misses_rtol_is_refined_with_its_factor():
    # the factor of a slightly wrong matrix (1e-8 relative) leaves a 1e-8 residual, above
    # rtol 1e-10; iterative refinement with that same factor contracts it by ~1e-8 a step
    from femkit.solvers.direct import factorize
    from femkit.solvers.core.norms import norm2

    A = sp.csr_matrix(sp.diags([-1.0, 2.5, -1.0], [-1, 0, 1], shape=(50, 50)))
    b = np.linspace(1.0, 2.0, 50)
    s = SolverSpec("direct").session()
    x = s._checked_solve(factorize(sp.csr_matrix(A * (1.0 + 1e-8))), A, b, norm2(b), "direct")
    assert np.linalg.norm(b - A @ x) <= 1e-10 * np.linalg.norm(b)
    assert s.stats["refinements"] >= 1


def test_a_residual_out_of_rtols_reach_is_accepted_only_up_to_the_callers_accept():
    # stiff pairs (K 1e6, mass 1e-3): rounding alone leaves a relative residual ~1e-7, which
    # no refinement removes; the verdict stays rtol's unless the caller (a Newton direction)
    # accepts more, and then it says so (inexact_solves)
    A, b = _stiff_pairs(1e6), np.ones(40)
    s = SolverSpec("direct").session()
    with pytest.raises(SolverError, match="missed the residual rule"):
        s.solve(A, b, refactor=True)
    x = s.solve(A, b, refactor=True, accept=1e-3)
    rel = np.linalg.norm(b - A @ x) / np.linalg.norm(b)
    assert 1e-10 < rel <= 1e-3
    assert s.stats["inexact_solves"] == 1
    with pytest.raises(SolverError, match="missed the residual rule"):
        s.solve(A, b, refactor=True, accept=1e-12)
