"""Iteration-count theory and cross-checks against SciPy and pyamg."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.solvers import cg, get_preconditioner, pcg, solve
from femkit.solvers.preconditioners import ic0


def _rhs(n, draw=0):
    return np.random.default_rng(draw).standard_normal(n)


def test_cg_iterations_double_per_halving_of_h(builders):
    # kappa(A) ~ h^-2, so CG iterations ~ sqrt(kappa) ~ h^-1: ratio ~2 per halving.
    # A smooth rhs (f = 1) keeps the count a property of the spectrum, not of the vector.
    its = []
    for m in (15, 31, 63):
        A = builders["poisson"](m)
        its.append(cg(A, np.ones(A.shape[0]), rtol=1e-8).iterations)
    ratios = np.diff(np.log2(its))
    assert np.all((ratios > 0.8) & (ratios < 1.2)), its


def test_ic0_pcg_needs_clearly_fewer_iterations_than_cg(builders):
    A = builders["poisson"](63)
    b = np.ones(A.shape[0])
    n_cg = solve(A, b, method="cg", rtol=1e-8).iterations
    n_ic = solve(A, b, method="pcg", preconditioner="ic0", rtol=1e-8).iterations
    assert n_cg / n_ic > 2.2, (n_cg, n_ic)  # Saad (2003) ch. 10; measured ~2.7x at rtol 1e-8


def test_jacobi_pcg_equals_cg_on_constant_diagonal(builders):
    A = builders["poisson"](31)
    b = _rhs(A.shape[0])
    r_cg = solve(A, b, method="cg")
    r_j = solve(A, b, method="pcg", preconditioner="jacobi")
    assert r_j.iterations == r_cg.iterations
    np.testing.assert_allclose(r_j.x, r_cg.x, rtol=1e-9, atol=1e-12)


def test_cg_matches_scipy_iteration_count(builders):
    from scipy.sparse.linalg import cg as scipy_cg

    A = builders["poisson"](40)
    b = _rhs(A.shape[0], 7)
    count = []
    x_sp, info = scipy_cg(A, b, rtol=1e-8, callback=lambda xk: count.append(1))
    ours = cg(A, b, rtol=1e-8)
    assert info == 0 and ours.converged
    assert abs(ours.iterations - len(count)) <= 2
    np.testing.assert_allclose(ours.x, x_sp, rtol=1e-6 * np.linalg.norm(x_sp) / np.abs(x_sp).min())


_CONDS: dict = {}


def _cond(case, A):
    if case not in _CONDS:
        ev = np.linalg.eigvalsh(A.toarray())
        _CONDS[case] = ev[-1] / ev[0]
    return _CONDS[case]


@pytest.mark.parametrize("flavour", ["amg_sa", "amg_rs"])
@pytest.mark.parametrize("case", ["poisson", "contrast"])
def test_amg_pcg_matches_pyamg_own_solve(flavour, case, builders):
    import pyamg

    A = builders[case](30)
    b = _rhs(A.shape[0], 11)
    build = pyamg.smoothed_aggregation_solver if flavour == "amg_sa" else pyamg.ruge_stuben_solver
    ml = build(A)
    hist = []
    x_py = ml.solve(b, tol=1e-8, accel="cg", residuals=hist, maxiter=500)
    ours = solve(A, b, method="pcg", preconditioner=flavour, rtol=1e-8)
    assert ours.converged
    assert abs(ours.iterations - (len(hist) - 1)) <= 2, (ours.iterations, len(hist) - 1)
    rel = np.linalg.norm(ours.x - x_py) / np.linalg.norm(x_py)
    cond_bound = 1e-8 * _cond(case, A)
    assert rel <= 2 * cond_bound
    assert rel <= 1e-5


def test_ic0_is_symmetric_and_exact_on_pattern(builders):
    A = builders["contrast"](12)
    M = ic0.build(A)
    rng = np.random.default_rng(2)
    u, v = rng.standard_normal((2, A.shape[0]))
    assert u @ M(v) == pytest.approx(v @ M(u), rel=1e-12)
    L = M.info["factor"]
    # IC(0): L L^T equals A on the pattern of A (the zero-fill property)
    LLt = (L @ L.T).tocsr()
    pattern = A.copy()
    pattern.data[:] = 1.0
    diff = (LLt - A).multiply(pattern)
    assert abs(diff).max() <= 1e-10 * abs(A).max()
    assert sp.tril(L, -1).nnz + L.shape[0] == sp.tril(A).nnz  # no fill


def test_ic0_exact_cholesky_on_tridiagonal(builders):
    A = builders["laplace_1d"](30)
    M = ic0.build(A)
    b = _rhs(30)
    from scipy.sparse.linalg import spsolve

    np.testing.assert_allclose(M(b), spsolve(A.tocsc(), b), rtol=1e-10)
    assert pcg(A, b, M=M).iterations == 1


def test_ic0_breakdown_is_shifted_and_reported():
    # SPD but IC(0) meets a negative pivot (Kershaw-type matrix)
    A = sp.csr_matrix(np.array([[3.0, -2.0, 0.0, 2.0],
                                [-2.0, 3.0, -2.0, 0.0],
                                [0.0, -2.0, 3.0, -2.0],
                                [2.0, 0.0, -2.0, 3.0]]))
    assert np.linalg.eigvalsh(A.toarray()).min() > 0
    M = ic0.build(A)
    assert M.info["shift"] > 0 and M.info["tries"] > 1
    res = solve(A, np.ones(4), method="pcg", preconditioner="ic0")
    assert res.converged and res.info["preconditioner_info"]["shift"] > 0


@pytest.mark.parametrize("flavour", ["amg_sa", "amg_rs"])
@pytest.mark.parametrize("cycle", ["V", "W"])
def test_amg_application_equals_pyamg_preconditioner(flavour, cycle, builders):
    A = builders["aniso"](30)
    M = get_preconditioner(flavour)(A, cycle=cycle)
    # pyamg was given 2^-e A (femkit normalises A's units for it): its cycle approximates 2^e A^-1
    pyamg_cycle = M.info["hierarchy"].aspreconditioner(cycle=cycle)
    ref = np.ldexp(pyamg_cycle.matvec(_rhs(A.shape[0], 4)), -M.info["scale_exponent"])
    r = _rhs(A.shape[0], 4)
    np.testing.assert_allclose(M(r), ref, rtol=1e-12, atol=1e-14 * np.abs(ref).max())
    u, v = _rhs(A.shape[0], 5), _rhs(A.shape[0], 6)
    assert u @ M(v) == pytest.approx(v @ M(u), rel=1e-8)  # symmetric V-cycle -> SPD for CG
