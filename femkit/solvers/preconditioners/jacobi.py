"""Jacobi (diagonal) preconditioner ``M = D^-1``."""

from __future__ import annotations

import time

from ..core.checks import as_operator, check_positive_diagonal, diagonal_of
from .base import Preconditioner


def build(A, *, diagonal=None) -> Preconditioner:
    """``M r = r / diag(A)``; a zero, negative or non-finite diagonal raises
    :class:`~femkit.errors.NotSPDError` (``M`` would not be SPD).

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> M = build(sp.diags([2.0, 4.0]))
    >>> M(np.ones(2)).tolist(), M.name
    ([0.5, 0.25], 'jacobi')
    """
    t0 = time.perf_counter()
    A = as_operator(A)
    d = diagonal_of(A, diagonal)
    check_positive_diagonal(d, what="the jacobi preconditioner")
    inv = 1.0 / d

    def apply(r):
        return inv * r

    return Preconditioner("jacobi", apply, A.shape[0], time.perf_counter() - t0,
                          {"min_diagonal": float(d.min()), "max_diagonal": float(d.max())})
