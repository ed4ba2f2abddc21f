"""The invertible SVD of one small matrix, compiled (Irving, Teran & Fedkiw 2004)."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def det_small(A):  # pragma: no cover - compiled
    """Determinant of a 2x2 or 3x3 matrix."""
    if A.shape[0] == 2:
        return A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    return (A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
            - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
            + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]))


@numba.njit(cache=True)
def signed_svd(F):  # pragma: no cover - compiled
    """``U, s, V`` with ``F = U diag(s) V^T``, ``det U = det V = 1``; ``s`` by decreasing
    magnitude, the last one negative when ``det F < 0``."""
    d = F.shape[0]
    U, s, Vt = np.linalg.svd(F)
    V = np.ascontiguousarray(Vt.T)
    if det_small(U) < 0.0:
        for a in range(d):
            U[a, d - 1] = -U[a, d - 1]
        s[d - 1] = -s[d - 1]
    if det_small(V) < 0.0:
        for a in range(d):
            V[a, d - 1] = -V[a, d - 1]
        s[d - 1] = -s[d - 1]
    return U, s, V
