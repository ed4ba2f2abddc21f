"""Preconditioned conjugate gradients (Saad 2003, algorithm 9.1, with ``M ~ A^-1``), vectorised.

Iteration (Saad, Alg. 9.1), ``z = M r``::

    alpha = (r, z) / (p, A p);  x += alpha p;  r -= alpha A p
    beta = (r_new, z_new) / (r, z);  p = z_new + beta p

Every iteration checks ``p^T A p > 0`` (else ``reason="breakdown"``, "indefinite
direction"), ``r^T z > 0`` (else breakdown: the preconditioner is not SPD), non-finite
values (``reason="non-finite"``) and stagnation (the best residual has not improved for
``stagnation_window`` iterations). The hot loop is one matrix-vector product, one
preconditioner application, two (three with ``M``) dot products and three BLAS ``axpy``
updates, with no temporaries for the vector updates.
"""

from __future__ import annotations


import math
from typing import Callable

import numpy as np
from scipy.linalg.blas import daxpy

from .core.checks import Problem, Replacement, as_apply, dependency_boundary, prepare, zero_rhs_result
from .core.norms import curvature_check, inner_rounding, norm2
from .core.result import SolveResult

#: Smallest stagnation window: iterations without a new best residual after which the iteration
#: is declared stagnant. The default window is ``max(STAGNATION_WINDOW, n)``: CG's residual norm is
#: not monotone (its A-norm error is), and on high-contrast problems it can stay above its initial
#: value for thousands of iterations before converging (checkerboard contrast 1e4, n = 16k: above
#: the initial residual beyond iteration 1000, converged at 6634), while in exact arithmetic CG
#: terminates within n iterations, so a window of n never declares progress stagnant too early.
STAGNATION_WINDOW = 1000


def _krylov_loop(prob: Problem, apply_M: Callable | None, *, method: str, callback=None,
                 stagnation_window: int | None = None,
                 raise_on_breakdown: bool = False) -> SolveResult:
    """Shared CG / PCG loop (``apply_M=None``: plain CG, ``z = r`` without a copy).

    Runs on the normalised system in cycles with residual replacement
    (:class:`~femkit.solvers.core.checks.Replacement`): a cycle ends when the recursive residual meets
    the tolerance or has not reached a new minimum for ``stagnation_window`` iterations; the
    true residual then decides between converged, stagnation and a restart of the recursion.
    """
    from ..errors import InputError, NotSPDError

    window = max(STAGNATION_WINDOW, prob.n) if stagnation_window is None else stagnation_window
    cyc = Replacement(prob)
    matvec, maxiter, x = prob.matvec, prob.maxiter, cyc.x
    k, ended = 0, ""
    with np.errstate(over="ignore", invalid="ignore"):
        while True:
            r, rr, stop = cyc.start(k, ended=ended, window=window)
            if stop:
                reason, message = stop
                break
            x = cyc.x
            if apply_M is None:
                z, rz = r, rr
            else:
                z = apply_M(r)
                if np.shape(z) != r.shape:
                    raise InputError(f"the preconditioner returned shape {np.shape(z)} for a "
                                     f"residual of shape {r.shape}; M(r) must return an array "
                                     f"of r's shape")
                rz = float(np.dot(r, z))
            reason, message = _rz_failure(rz, r, z, k) or ("maxiter", "")
            if reason != "maxiter":
                break
            p = np.array(z, dtype=np.float64, copy=True)
            best, best_k = math.sqrt(rr), k
            ended = ""
            while k < maxiter:
                q = matvec(p)
                pq = float(np.dot(p, q))
                failure = curvature_check(pq, p, q, k=k + 1)
                if failure:
                    reason, message = failure
                    break
                alpha = rz / pq
                daxpy(p, x, a=alpha)
                daxpy(q, r, a=-alpha)
                if apply_M is None:
                    rr = float(np.dot(r, r))
                    rz_new = rr
                else:
                    z = apply_M(r)
                    rz_new = float(np.dot(r, z))
                    rr = float(np.dot(r, r))
                k += 1
                res = math.sqrt(rr) if rr >= 0 else float("nan")
                ended, stop = cyc.record(res, k, callback)
                if stop:
                    reason, message = stop
                if ended or stop:
                    break
                if res < best:
                    best, best_k = res, k
                elif k - best_k >= window:
                    ended = "window"
                    break
                failure = _rz_failure(rz_new, r, z, k)
                if failure:
                    reason, message = failure
                    break
                beta = rz_new / rz
                rz = rz_new
                p *= beta
                p += z
            else:
                reason, message = "maxiter", (
                    f"maxiter = {maxiter} reached; residual {cyc.unscaled(res):.3e} > "
                    f"tolerance {prob.tolerance:.3e}")
            if not ended:   # breakdown, non-finite or maxiter inside the recursion
                break
    if reason == "breakdown" and raise_on_breakdown:
        raise NotSPDError(f"{method}: {message}")
    return cyc.finish(iterations=k, reason=reason, message=message, method=method)


def _rz_failure(rz: float, r: np.ndarray, z: np.ndarray, k: int) -> tuple[str, str] | None:
    """``r^T M r`` must be positive (on the normalised system its sign is free of underflow);
    a non-positive value is judged relative to ``||r|| ||M r||`` for the message."""
    if rz > 0:
        return None
    if not math.isfinite(rz):
        return "non-finite", f"r^T M r = {rz} at iteration {k}"
    size = "within rounding of 0" if abs(rz) <= inner_rounding(r.size) * norm2(r) * norm2(z) \
        else "negative"
    return "breakdown", (f"r^T M r = {rz:.3e} ({size}, relative to ||r|| ||M r||) at iteration "
                         f"{k}: the preconditioner is not positive definite")


def pcg(A, b, x0=None, *, rtol: float | None = None, atol: float | None = None, maxiter: int | None = None,
        M=None, callback=None, check_symmetry: bool = True,
        stagnation_window: int | None = None,
        raise_on_breakdown: bool = False) -> SolveResult:
    """Preconditioned conjugate gradients for a symmetric positive definite ``A``.

    Stops when the recursive residual satisfies ``||r_k|| <= max(rtol ||b||, atol)``;
    ``converged`` is then confirmed with the true residual ``||b - A x||`` recomputed at
    exit (if only the recursive one met the rule: ``converged=False``,
    ``reason="stagnation"``).

    Parameters
    ----------
    A : sparse matrix, ndarray or LinearOperator, shape (n, n)
        Symmetric positive definite. Explicit matrices are checked for symmetry once
        (``||A - A^T||_inf / ||A||_inf <= 1e-10``, else :class:`~femkit.errors.NotSPDError`).
    b : ndarray, shape (n,)
    x0 : ndarray, optional
        Initial guess (zeros by default); ``residuals[0] = ||b - A x0||``.
    rtol, atol : float
        Relative and absolute tolerance (non-negative, not both zero).
    maxiter : int, optional
        Iteration limit; default ``10 n``.
    M : callable, LinearOperator, matrix or preconditioner object, optional
        SPD approximation of ``A^-1`` applied as ``z = M(r)``; ``None`` means plain CG.
    callback : callable, optional
        ``callback(xk)`` after every iteration.
    check_symmetry : bool
        Skip the one-off symmetry check when False.
    stagnation_window : int, optional
        Stop with ``reason="stagnation"`` when the residual has not reached a new minimum
        for this many iterations; default ``max(1000, n)`` (see :data:`STAGNATION_WINDOW`).
    raise_on_breakdown : bool
        Raise :class:`~femkit.errors.NotSPDError` instead of returning ``reason="breakdown"``.

    Returns
    -------
    SolveResult

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(5, 5))
    >>> res = pcg(A, np.ones(5), M=lambda r: r / 2.0)
    >>> res.converged, res.iterations, bool(np.allclose(A @ res.x, 1.0))
    (True, 3, True)
    """
    method = "pcg" if M is not None else "cg"
    prob = prepare(A, b, x0, rtol=rtol, atol=atol, maxiter=maxiter, method=method,
                   symmetric=True, check_symmetry=check_symmetry)
    if prob.b_is_zero:
        return zero_rhs_result(prob, method=method)
    pc = f" with preconditioner {getattr(M, 'name', type(M).__name__)!r}" if M is not None else ""
    with dependency_boundary(f"{method}{pc}", prob.A):   # e.g. a pyamg cycle failing
        return _krylov_loop(prob, as_apply(M, prob.n), method=method, callback=callback,
                            stagnation_window=stagnation_window,
                            raise_on_breakdown=raise_on_breakdown)
