"""Adversarial review of the solver layer: inputs a trusting user may hand in, and the
promises of the result object checked on every method (complex and non-finite data, unknown
options, dense matrices, the stopping rule at its boundary, timing, history semantics)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from femkit.errors import InputError
from femkit.solvers import direct, factorize, get_preconditioner, get_solver, jacobi, pcg, solve
from femkit.solvers.preconditioners import ic0

METHODS = ["jacobi", "sd", "cg", "pcg", "direct"]
ITERATIVE = ["jacobi", "sd", "cg", "pcg"]
PRECONDITIONERS = ["jacobi", "ic0", "amg_sa", "amg_rs"]


def lap1d(n: int) -> sp.csr_matrix:
    return sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n), format="csr")


# ---------------------------------------------------------------- complex / non-numeric data


@pytest.mark.parametrize("method,what", [
    pytest.param(m, w, id=f"{w}-{m}") for w in ["b", "A-sparse", "A-dense", "x0"]
    for m in METHODS if not (m == "direct" and w == "x0")])  # direct ignores x0 (documented)
def test_complex_input_is_refused_not_truncated(method, what):
    # casting complex to float64 silently drops the imaginary part: a wrong answer
    A, b, x0 = lap1d(8), np.ones(8), None
    if what == "b":
        b = b + 1j
    elif what == "A-sparse":
        A = A * (1 + 1j)
    elif what == "A-dense":
        A = A.toarray() * (1 + 1j)
    else:
        x0 = np.ones(8) * 1j
    with pytest.raises(InputError, match="complex"):
        get_solver(method)(A, b, x0)


@pytest.mark.parametrize("pc", PRECONDITIONERS)
def test_complex_matrix_refused_by_preconditioners(pc):
    with pytest.raises(InputError, match="complex"):
        get_preconditioner(pc)(lap1d(8) * (1 + 1j))


@pytest.mark.parametrize("method", METHODS)
def test_non_numeric_rhs_is_an_input_error(method):
    with pytest.raises(InputError, match="b"):
        get_solver(method)(lap1d(4), np.array(["a", "b", "c", "d"]))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("kind", ["sparse", "dense"])
def test_non_finite_matrix_entries_are_an_input_error(method, kind):
    # before: jacobi reported "diverged ... not diagonally dominant enough", CG "r^T M r = nan"
    A = lap1d(6).tolil()
    A[2, 3] = A[3, 2] = np.nan
    A = A.tocsr() if kind == "sparse" else A.toarray()
    with pytest.raises(InputError, match="non-finite"):
        get_solver(method)(A, np.ones(6))


@pytest.mark.parametrize("pc", PRECONDITIONERS)
def test_non_finite_matrix_refused_by_preconditioners(pc):
    A = lap1d(6).tolil()
    A[2, 3] = A[3, 2] = np.inf
    with pytest.raises(InputError, match="non-finite"):
        get_preconditioner(pc)(A.tocsr())


# ---------------------------------------------------------------- options


@pytest.mark.parametrize("method", METHODS)
def test_unknown_option_names_the_option(method):
    with pytest.raises(InputError, match=r"unknown option.*'omgea'"):
        solve(lap1d(5), np.ones(5), method=method, omgea=0.5)


@pytest.mark.parametrize("pc", PRECONDITIONERS)
def test_unknown_preconditioner_option_names_the_option(pc):
    with pytest.raises(InputError, match=r"unknown option.*'bogus'"):
        solve(lap1d(5), np.ones(5), method="pcg", preconditioner=pc,
              preconditioner_options={"bogus": 1})


@pytest.mark.parametrize("where, data, text", [
    ("solver", {"method": "cholesky", "options": {"engine": "mumps"}},
     "solver.options: unknown cholesky engine 'mumps'; valid cholesky engines: cholespy, cholmod, pardiso"),
    ("linear_solver", {"method": "cholesky", "options": {"ordering": "rcm"}},
     "linear_solver.options: unknown cholesky ordering 'rcm'"),
], ids=["engine", "ordering"])
def test_a_bad_option_value_is_named_when_the_spec_is_built(where, data, text):
    """Declared option values (``fn.option_choices``) are checked when a file is loaded, with the
    key path and the valid values, not at the first solve after the mesh is built; no solver
    library is needed to say so."""
    from femkit.errors import UnknownNameError
    from femkit.solvers import SolverSpec

    with pytest.raises(UnknownNameError) as info:
        SolverSpec.from_mapping(data, where)
    assert str(info.value).startswith(text)


def test_known_options_still_pass_through():
    A, b = lap1d(20), np.ones(20)
    assert solve(A, b, method="jacobi", omega=0.8, maxiter=5000).info["omega"] == 0.8
    res = solve(A, b, method="pcg", preconditioner="amg_sa",
                preconditioner_options={"max_coarse": 5, "coarse_solver": "splu"})
    assert res.converged
    assert solve(A, b, method="pcg", preconditioner="ic0",
                 preconditioner_options={"shift": 1e-2}).info["preconditioner_info"]["shift"] == 1e-2


@pytest.mark.parametrize("shift", [-1.0, float("nan")], ids=["negative", "nan"])
def test_ic0_invalid_shift_raises(shift):
    with pytest.raises(InputError, match="shift"):
        ic0.build(lap1d(5), shift=shift)


@pytest.mark.parametrize("omega", [np.float32(0.5), np.float64(0.5), 1], ids=["f32", "f64", "int"])
def test_jacobi_accepts_any_real_omega(omega):
    assert jacobi(lap1d(6), np.ones(6), omega=omega, maxiter=2000).converged


def test_jacobi_refuses_bool_omega():
    with pytest.raises(InputError, match="omega"):
        jacobi(lap1d(6), np.ones(6), omega=True)


def test_preconditioner_output_shape_checked():
    with pytest.raises(InputError, match="preconditioner"):
        pcg(lap1d(6), np.ones(6), M=lambda r: r[:, None] / 2.0)


# ---------------------------------------------------------------- dense input on the default path


@pytest.mark.parametrize("pc", PRECONDITIONERS)
def test_dense_matrix_works_with_every_preconditioner(pc):
    A = lap1d(30)
    b = np.linspace(1.0, 2.0, 30)
    res = solve(A.toarray(), b, method="pcg", preconditioner=pc)
    assert res.converged
    np.testing.assert_allclose(res.x, np.linalg.solve(A.toarray(), b), rtol=1e-6)


# ---------------------------------------------------------------- direct on indefinite symmetric


@pytest.mark.parametrize("eps", [1e-6, 1e-10, 1e-14])
def test_direct_symmetric_indefinite_with_positive_diagonal(eps):
    # cond(A) = 3, symmetric, positive diagonal but indefinite (eigenvalues eps +- 1): the auto
    # "spd" mode with pure diagonal pivoting took a pivot eps and lost ~1/eps accuracy
    A = sp.csr_matrix(np.array([[eps, 1, 0, 0], [1, eps, 0, 0], [0, 0, 2, 1], [0, 0, 1, 2.0]]))
    b = np.array([1.0, 2.0, 3.0, 4.0])
    res = direct(A, b, rtol=1e-12)
    assert res.converged, res.message
    np.testing.assert_allclose(res.x, np.linalg.solve(A.toarray(), b), rtol=1e-12, atol=1e-13)


def test_direct_spd_keeps_symmetric_mode_and_fill():
    from scipy.sparse.linalg import splu

    A = (sp.kron(lap1d(30), sp.identity(30)) + sp.kron(sp.identity(30), lap1d(30))).tocsc()
    F = factorize(A)
    ref = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
               options=dict(SymmetricMode=True))
    assert F.symmetric
    assert F.info["nnz_L"] + F.info["nnz_U"] == ref.L.nnz + ref.U.nnz


# ---------------------------------------------------------------- result semantics


@pytest.mark.parametrize("method", METHODS)
def test_solve_time_filled_when_called_directly(method):
    res = get_solver(method)(lap1d(50), np.ones(50))
    assert res.solve_time > 0.0
    json.dumps(res.summary())


@pytest.mark.parametrize("method", ITERATIVE)
def test_zero_rhs_history_starts_with_initial_residual(method):
    A, x0 = lap1d(6), np.arange(6.0)
    res = get_solver(method)(A, np.zeros(6), x0=x0)
    assert res.converged and np.all(res.x == 0.0)
    assert res.residuals[0] == pytest.approx(np.linalg.norm(A @ x0))
    assert len(res.residuals) == res.iterations + 1


@pytest.mark.parametrize("method", ITERATIVE)
def test_stopping_rule_at_its_boundary(method):
    A, b = lap1d(12), np.linspace(-1.0, 1.0, 12)
    x0 = np.full(12, 0.25)
    r0 = float(np.linalg.norm(b - A @ x0))
    at = get_solver(method)(A, b, x0, rtol=1e-30, atol=r0)
    assert at.converged and at.iterations == 0 and at.reason == "converged"
    below = get_solver(method)(A, b, x0, rtol=1e-30, atol=np.nextafter(r0, 0.0), maxiter=1)
    assert below.iterations == 1


def _spd(draw: int, n: int, cond_exp: float):
    rng = np.random.default_rng(draw)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    lam = np.logspace(0.0, cond_exp, n)
    A = (Q * lam) @ Q.T
    A = 0.5 * (A + A.T)
    return A, rng.standard_normal(n), rng.standard_normal(n)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(key=st.integers(0, 2**31 - 1), n=st.integers(1, 12), cond_exp=st.floats(0.0, 9.0),
       method=st.sampled_from(METHODS + ["pcg-ic0", "pcg-amg"]),
       rtol=st.sampled_from([1e-2, 1e-8, 1e-14]), maxiter=st.integers(0, 30),
       dense=st.booleans(), use_x0=st.booleans())
def test_converged_never_contradicts_true_residual(key, n, cond_exp, method, rtol, maxiter,
                                                   dense, use_x0):
    A, b, x0 = _spd(key, n, cond_exp)
    M = A if dense else sp.csr_matrix(A)
    name, _, pc = method.partition("-")
    kw = dict(rtol=rtol, x0=x0 if use_x0 else None)
    if name != "direct":
        kw["maxiter"] = maxiter
    if name == "pcg":
        kw["preconditioner"] = pc or "jacobi"
    res = solve(M, b, method=name, **kw)
    true = float(np.linalg.norm(b - A @ res.x))
    # same quantity up to the rounding of one product (sparse vs dense summation order)
    slack = 1e-14 * n * (np.linalg.norm(A, 2) * np.linalg.norm(res.x) + np.linalg.norm(b))
    assert res.true_residual == pytest.approx(true, rel=1e-6, abs=slack)
    if res.converged:
        assert res.true_residual <= res.tolerance
    assert res.tolerance == pytest.approx(rtol * np.linalg.norm(b))
    assert len(res.residuals) == res.iterations + 1
    if name != "direct":
        assert res.iterations <= maxiter
    assert res.reason in ("converged", "maxiter", "breakdown", "stagnation", "non-finite", "direct")
    json.dumps(res.summary())


# ---------------------------------------------------------------- non-finite operator, breakdown index


@pytest.mark.parametrize("method", ITERATIVE)
def test_operator_returning_nan_is_named_at_the_initial_residual(method):
    # before: jacobi said "diverged ... not diagonally dominant enough", sd "indefinite
    # direction", cg "r^T M r = nan": none of them the actual fault (A x0 is NaN)
    from scipy.sparse.linalg import LinearOperator

    A = lap1d(6)
    op = LinearOperator(A.shape, matvec=lambda x: (A @ x) * np.nan, dtype=np.float64)
    kw = {"diagonal": A.diagonal()} if method == "jacobi" else {}
    if method == "pcg":
        kw["M"] = lambda r: r / 2.0
    res = get_solver(method)(op, np.ones(6), **kw)
    assert res.reason == "non-finite" and not res.converged
    assert res.iterations == 0 and len(res.residuals) == 1
    assert "initial residual" in res.message
    assert np.all(np.isfinite(res.x))


def test_breakdown_iteration_index():
    # diag(2, 1, -1), b = 1: the first step is fine (p^T A p = 2), the second direction has
    # p^T A p < 0; one completed iteration, the message names iteration 2
    res = get_solver("cg")(sp.diags([2.0, 1.0, -1.0], format="csr"), np.ones(3))
    assert res.reason == "breakdown" and not res.converged
    assert res.iterations == 1 and len(res.residuals) == 2
    assert "at iteration 2" in res.message
