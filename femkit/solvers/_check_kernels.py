"""numba kernel of the symmetry check (imported lazily by :mod:`.checks`; imports numba)."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def asymmetry_sums(indptr, indices, data):  # pragma: no cover - compiled
    """Row sums of ``|A - A^T|`` and of ``|A|`` for a CSR matrix with sorted, unique column
    indices, in one pass: entry ``a_ij`` looks up ``a_ji`` by bisection in row ``j``; a partner
    that is not stored puts ``|a_ij|`` in both rows ``i`` and ``j`` (row ``i`` of ``A - A^T``
    has it from ``A``, row ``j`` from ``A^T``). Returns ``(max row sum of |A - A^T|, max row sum
    of |A|)``."""
    n = indptr.shape[0] - 1
    diff = np.zeros(n)
    mx = 0.0
    for i in range(n):
        row = 0.0
        for t in range(indptr[i], indptr[i + 1]):
            j = indices[t]
            v = data[t]
            row += abs(v)
            lo = indptr[j]
            hi = indptr[j + 1]
            while lo < hi:
                mid = (lo + hi) >> 1
                if indices[mid] < i:
                    lo = mid + 1
                else:
                    hi = mid
            if lo < indptr[j + 1] and indices[lo] == i:
                diff[i] += abs(v - data[lo])
            else:
                diff[i] += abs(v)
                diff[j] += abs(v)
        if row > mx:
            mx = row
    worst = 0.0
    for i in range(n):
        if diff[i] > worst:
            worst = diff[i]
    return worst, mx
