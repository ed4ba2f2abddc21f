"""Steepest descent (Saad 2003, section 5.3.1), vectorised.

For SPD ``A``: ``r = b - A x``, ``alpha = (r, z) / (z, A z)`` with ``z = M r`` (``z = r``
without preconditioner), ``x += alpha z``, ``r -= alpha A z``. One product per iteration;
the residual is recursive, re-checked against the true residual at exit.
"""

from __future__ import annotations

from .defaults import DEFAULT_RTOL

import math

import numpy as np
from scipy.linalg.blas import daxpy

from .checks import (as_apply, finish, nonfinite_initial_residual, prepare, record_iteration,
                     zero_rhs_result)
from .result import SolveResult


def steepest_descent(A, b, x0=None, *, rtol: float = DEFAULT_RTOL, atol: float = 0.0,
                     maxiter: int | None = None, M=None, callback=None,
                     check_symmetry: bool = True) -> SolveResult:
    """Steepest descent for SPD ``A`` until ``||b - A x|| <= max(rtol ||b||, atol)``.

    Default ``maxiter = 10 n``. ``z^T A z <= 0`` stops with ``reason="breakdown"``
    (indefinite direction); a nonsymmetric explicit ``A`` raises
    :class:`~femkit.errors.NotSPDError`. ``converged`` is confirmed on the true residual.

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.diags([-1.0, 4.0, -1.0], [-1, 0, 1], shape=(6, 6))
    >>> res = steepest_descent(A, np.ones(6))
    >>> res.converged, res.method
    (True, 'sd')
    """
    prob = prepare(A, b, x0, rtol=rtol, atol=atol, maxiter=maxiter, method="sd",
                   symmetric=True, check_symmetry=check_symmetry)
    if prob.rhs_norm == 0.0:
        return zero_rhs_result(prob, method="sd")
    apply_M = as_apply(M, prob.n)
    matvec, x, tol = prob.matvec, prob.x, prob.tolerance
    r = prob.b - matvec(x)
    res = float(np.linalg.norm(r))
    residuals = [res]
    reason, message, k, met = "maxiter", nonfinite_initial_residual(res), 0, res <= tol
    if message:
        reason = "non-finite"
    elif met:
        reason = "converged"
    while reason == "maxiter" and k < prob.maxiter:
        z = r if apply_M is None else apply_M(r)
        q = matvec(z)
        zq = float(np.dot(z, q))
        if not zq > 0:
            reason = "breakdown" if math.isfinite(zq) else "non-finite"
            message = (f"indefinite direction: z^T A z = {zq:.3e} at iteration {k + 1}"
                       if reason == "breakdown" else f"z^T A z = {zq} at iteration {k + 1}")
            break
        alpha = float(np.dot(r, z)) / zq
        daxpy(z, x, a=alpha)
        daxpy(q, r, a=-alpha)
        k += 1
        res = float(np.linalg.norm(r))
        bad = record_iteration(residuals, res, x, callback, k)
        if bad:
            reason, message = "non-finite", bad
            break
        if res <= tol:
            reason, met = "converged", True
    if reason == "maxiter":
        message = f"maxiter = {prob.maxiter} reached; residual {res:.3e} > tolerance {tol:.3e}"
    return finish(prob, iterations=k, residuals=residuals, reason=reason, message=message,
                  method="sd", recursive_met=met)
