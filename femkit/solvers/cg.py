"""Conjugate gradients (Hestenes & Stiefel 1952; Saad 2003, algorithm 6.18), the documented entry for unpreconditioned CG.

It shares the loop of :mod:`femkit.solvers.pcg` with ``z = r`` (no preconditioner copy),
so both carry the same checks: symmetry once, ``p^T A p > 0`` every iteration, non-finite
values, stagnation, and the true residual at exit.
"""

from __future__ import annotations


from .pcg import pcg
from .core.result import SolveResult


def cg(A, b, x0=None, *, rtol: float | None = None, atol: float | None = None, maxiter: int | None = None,
       M=None, callback=None, check_symmetry: bool = True,
       stagnation_window: int | None = None,
       raise_on_breakdown: bool = False) -> SolveResult:
    """Conjugate gradients for a symmetric positive definite ``A``.

    Stopping rule: ``||b - A x|| <= max(rtol ||b||, atol)``, tested on the recursive
    residual each iteration and confirmed on the true residual at exit (``converged`` is
    true only if the true residual meets it). Default ``maxiter = 10 n``.
    ``p^T A p <= 0`` stops with ``reason="breakdown"`` ("indefinite direction") unless
    ``raise_on_breakdown``; a nonsymmetric explicit ``A`` raises
    :class:`~femkit.errors.NotSPDError` (``check_symmetry=False`` skips that check).

    ``M`` is accepted for signature uniformity: given, this is PCG
    (see :func:`femkit.solvers.pcg.pcg` for all parameters).

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(50, 50))
    >>> res = cg(A, np.ones(50))
    >>> res.converged, res.iterations <= 50, res.reason
    (True, True, 'converged')
    """
    return pcg(A, b, x0, rtol=rtol, atol=atol, maxiter=maxiter, M=M, callback=callback,
               check_symmetry=check_symmetry, stagnation_window=stagnation_window,
               raise_on_breakdown=raise_on_breakdown)
