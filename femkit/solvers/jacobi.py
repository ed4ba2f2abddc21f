"""Weighted Jacobi iteration (Saad 2003, *Iterative Methods for Sparse Linear Systems*, section 4.1), vectorised.

``x_{k+1} = x_k + omega D^-1 r_k`` with ``r_k = b - A x_k`` and ``D = diag(A)``; ``omega = 1``
is the classical Jacobi iteration. It converges for strictly diagonally dominant matrices,
and for SPD ``A`` exactly when ``0 < omega < 2 / lambda_max(D^-1 A)`` (``omega = 2/3`` is the
classical smoothing weight). A divergent iteration (residual above :data:`DIVERGENCE_FACTOR`
times the initial one) stops with ``reason="non-finite"`` (returning the last iterate before) or
``"maxiter"``, never a silent NaN; a residual (the true one: recomputed every iteration) with no new
minimum for ``max(1000, n)`` iterations stops with ``reason="stagnation"`` at the best iterate.
"""

from __future__ import annotations


import math
import numbers

import numpy as np

from ..errors import InputError
from .core.checks import (as_apply, check_positive_diagonal, dependency_boundary, diagonal_of,
                     finish, nonfinite_initial_residual, prepare, zero_rhs_result)
from .core.norms import ldexp_saturating, norm2, scaled, unscale, unscale_all
from .pcg import STAGNATION_WINDOW
from .core.result import SolveResult


#: Growth of the residual over the initial one at which the iteration is declared divergent
#: (``reason="non-finite"``): a relative, scale-invariant test, met long before the iterates of
#: any representable system overflow, so the verdict and its iteration do not depend on units.
DIVERGENCE_FACTOR = 1e100


def jacobi(A, b, x0=None, *, rtol: float | None = None, atol: float | None = None, maxiter: int | None = None,
           M=None, callback=None, omega: float = 1.0, diagonal=None) -> SolveResult:
    """Weighted Jacobi: ``x += omega D^-1 (b - A x)`` until ``||b - A x|| <= max(rtol ||b||, atol)``.

    The residual is recomputed from ``A`` every iteration (it costs the one product the
    update needs anyway), so the recorded history is the true residual. Default
    ``maxiter = 10 n``.

    Parameters
    ----------
    A : sparse matrix, ndarray or LinearOperator
        Needs a positive diagonal (else :class:`~femkit.errors.NotSPDError`); for a
        LinearOperator pass ``diagonal=``. Symmetry is not required.
    M : optional
        Replaces ``D^-1`` (preconditioned Richardson ``x += omega M r``).
    omega : float
        Damping weight in ``(0, 2)``; default 1 (classical Jacobi).
    diagonal : ndarray, optional
        ``diag(A)``, required when ``A`` is a LinearOperator.

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.diags([-1.0, 4.0, -1.0], [-1, 0, 1], shape=(6, 6))
    >>> res = jacobi(A, np.ones(6), rtol=1e-10)
    >>> res.converged, bool(np.allclose(A @ res.x, 1.0))
    (True, True)
    """
    if isinstance(omega, bool) or not (isinstance(omega, numbers.Real) and 0.0 < omega < 2.0):
        raise InputError(f"jacobi: omega must be in (0, 2), got {omega!r}")
    prob = prepare(A, b, x0, rtol=rtol, atol=atol, maxiter=maxiter, method="jacobi")
    apply_M = as_apply(M, prob.n)
    if apply_M is None:
        d = diagonal_of(prob.A, diagonal)
        check_positive_diagonal(d, what="jacobi")
        winv = omega / d

        def apply_M(r):
            return winv * r
        scale = 1.0
    else:
        scale = float(omega)
    if prob.b_is_zero:
        return zero_rhs_result(prob, method="jacobi")
    # the normalised system 2^-e b (femkit.solvers.core.norms): exact scaling, so the iterates are
    # those on b; the residual is the true one every iteration, so there is no stagnation verdict
    e = prob.exponent
    matvec, b, x = prob.matvec, scaled(prob.b, -e), scaled(prob.x, -e)
    tol = ldexp_saturating(prob.tolerance, -e)
    with np.errstate(over="ignore", invalid="ignore"):
        r = b - matvec(x)
    res = norm2(r) if np.all(np.isfinite(r)) else float("inf")
    residuals = [res]
    reason, message, k = "maxiter", nonfinite_initial_residual(res), 0
    # the residual is the true one: a window without a new minimum is stagnation (the rounding
    # floor), and x goes back to the best iterate (Jacobi is stationary: a restart from it
    # repeats the iterations that found nothing better)
    window = max(STAGNATION_WINDOW, prob.n)
    best, best_k, best_x = res, 0, x
    if message:
        reason = "non-finite"
    elif res <= tol:
        reason = "converged"
    while reason == "maxiter" and k < prob.maxiter:
        with dependency_boundary("jacobi", prob.A):   # a user M from a dependency
            step = apply_M(r)
        x_new = x + step if scale == 1.0 else x + scale * step
        with np.errstate(over="ignore", invalid="ignore"):
            r_new = b - matvec(x_new)
            res = norm2(r_new) if np.all(np.isfinite(r_new)) else float("inf")
        if not res <= DIVERGENCE_FACTOR * residuals[0]:   # also NaN / inf
            reason = "non-finite"
            message = (f"jacobi diverged: the residual grew beyond {DIVERGENCE_FACTOR:.0e} times "
                       f"the initial one at iteration {k + 1} (last residual "
                       f"{unscale(residuals[-1], e):.3e}, initial {unscale(residuals[0], e):.3e}); "
                       f"A is not diagonally dominant enough for omega = {omega}; returning the "
                       f"last iterate before")
            break
        x, r = x_new, r_new
        k += 1
        residuals.append(res)
        if callback is not None:
            callback(scaled(x, e))
        if res <= tol:
            reason = "converged"
        elif res < best:
            best, best_k, best_x = res, k, x
        elif k - best_k >= window:
            reason = "stagnation"
            message = (f"stagnation: the true residual has not decreased for {window} iterations "
                       f"(best {unscale(best, e):.3e} at iteration {best_k}, the iterate returned; "
                       f"tolerance {prob.tolerance:.3e}): rounding errors limit the attainable "
                       f"accuracy")
            x = best_x
    if reason == "maxiter":
        growth = residuals[-1] / residuals[0] if residuals[0] > 0 else float("nan")
        message = (f"maxiter = {prob.maxiter} reached; residual {unscale(residuals[-1], e):.3e} > "
                   f"tolerance {prob.tolerance:.3e} (residual ratio to initial {growth:.3e}"
                   f"{', diverging' if growth > 1 else ''})")
    x = scaled(x, e)
    residuals = unscale_all(residuals, e)
    prob.x = x
    return finish(prob, iterations=k, residuals=residuals, reason=reason, message=message,
                  method="jacobi", info={"omega": float(omega)})
