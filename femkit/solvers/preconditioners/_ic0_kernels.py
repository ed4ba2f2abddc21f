"""numba kernels of the IC(0) preconditioner (imported lazily by :mod:`.ic0`; imports numba).

``L`` is stored as CSR of the lower triangle with sorted column indices, so the diagonal
is the last entry of every row.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def ic0_factor(indptr, indices, data, n):  # pragma: no cover - compiled
    """Overwrite ``data`` (lower triangle of A) with IC(0)'s ``L``; return ``-1`` on success,
    else the row whose pivot is not positive (``data`` is then partly overwritten)."""
    pos = np.full(n, -1, np.int64)
    for i in range(n):
        s = indptr[i]
        e = indptr[i + 1]
        for t in range(s, e):
            pos[indices[t]] = t
        for t in range(s, e - 1):
            k = indices[t]
            acc = data[t]
            for u in range(indptr[k], indptr[k + 1] - 1):
                pt = pos[indices[u]]
                if pt != -1:
                    acc -= data[pt] * data[u]
            data[t] = acc / data[indptr[k + 1] - 1]
        d = data[e - 1]
        for t in range(s, e - 1):
            d -= data[t] * data[t]
        for t in range(s, e):
            pos[indices[t]] = -1
        if not (d > 0.0) or not math.isfinite(d):
            return i
        data[e - 1] = math.sqrt(d)
    return -1


@numba.njit(cache=True)
def ic0_solve(lp, li, lx, up, ui, ux, inv_d, r, z):  # pragma: no cover - compiled
    """``z = (L L^T)^-1 r`` with ``L = strict lower (lp, li, lx) + diag(1 / inv_d)`` and
    ``L^T``'s strict upper part as CSR ``(up, ui, ux)``: two row-oriented substitutions
    (gathers only, multiplications by the inverse diagonal)."""
    n = r.shape[0]
    for i in range(n):
        acc = r[i]
        for t in range(lp[i], lp[i + 1]):
            acc -= lx[t] * z[li[t]]
        z[i] = acc * inv_d[i]
    for i in range(n - 1, -1, -1):
        acc = z[i]
        for t in range(up[i], up[i + 1]):
            acc -= ux[t] * z[ui[t]]
        z[i] = acc * inv_d[i]
