"""Steepest descent (Saad 2003, section 5.3.1), vectorised.

For SPD ``A``: ``r = b - A x``, ``alpha = (r, z) / (z, A z)`` with ``z = M r`` (``z = r``
without preconditioner), ``x += alpha z``, ``r -= alpha A z``. One product per iteration;
the residual is recursive: when it meets the tolerance the true residual is recomputed and, if it
does not, the recursion restarts from it (residual replacement, van der Vorst and Ye 2000);
stagnation is declared only when the true residual stops decreasing across a replacement.
"""

from __future__ import annotations


import math

import numpy as np
from scipy.linalg.blas import daxpy

from .core.checks import Replacement, as_apply, dependency_boundary, prepare, zero_rhs_result
from .core.norms import curvature_check
from .core.result import SolveResult


def steepest_descent(A, b, x0=None, *, rtol: float | None = None, atol: float | None = None,
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
    if prob.b_is_zero:
        return zero_rhs_result(prob, method="sd")
    apply_M = as_apply(M, prob.n)
    cyc = Replacement(prob)   # normalised system, residual replacement before any stagnation
    matvec = prob.matvec
    k, ended = 0, ""
    with np.errstate(over="ignore", invalid="ignore"), dependency_boundary("sd", prob.A):
        while True:
            r, rr, stop = cyc.start(k, ended=ended)
            if stop:
                reason, message = stop
                break
            x, ended = cyc.x, ""
            reason, message = "maxiter", ""
            while k < prob.maxiter:
                z = r if apply_M is None else apply_M(r)
                q = matvec(z)
                zq = float(np.dot(z, q))
                failure = curvature_check(zq, z, q, k=k + 1, what="z^T A z")
                if failure:
                    reason, message = failure
                    break
                k += 1
                alpha = float(np.dot(r, z)) / zq
                daxpy(z, x, a=alpha)
                daxpy(q, r, a=-alpha)
                res = math.sqrt(float(np.dot(r, r)))
                ended, stop = cyc.record(res, k, callback)
                if stop:
                    reason, message = stop
                if ended or stop:
                    break
            else:
                message = (f"maxiter = {prob.maxiter} reached; residual {cyc.unscaled(res):.3e} "
                           f"> tolerance {prob.tolerance:.3e}")
            if not ended:
                break
    return cyc.finish(iterations=k, reason=reason, message=message, method="sd")
