"""numba kernel of the symmetry check (imported lazily by :mod:`.checks`; imports numba)."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def asymmetry_sums(indptr, indices, data):  # pragma: no cover - compiled
    """Largest row sums of ``|A - A^T|`` and of ``|A|`` for a CSR matrix with sorted, unique
    column indices, in one pass over the rows and no search.

    Rows are visited in increasing order ``i``; the partner ``a_ji`` of an upper entry
    ``a_ij`` (``j > i``) sits in row ``j``'s lower part, whose columns are asked for in
    increasing order too, so a pointer per row (``ptr[j]``) walks that part once. A lower entry
    the pointer passes without a match had no upper partner: it counts in both rows (row ``j``
    of ``A - A^T`` has it from ``A``, row ``c`` from ``A^T``), as does an upper entry whose
    partner is missing. O(nnz), rows touched near the diagonal band.
    """
    n = indptr.shape[0] - 1
    diff = np.zeros(n)
    ptr = indptr[:n].copy()
    mx = 0.0
    for i in range(n):
        row = 0.0
        end = indptr[i + 1]
        for t in range(indptr[i], end):
            v = data[t]
            row += abs(v)
            j = indices[t]
            if j <= i:
                continue
            q = ptr[j]
            stop = indptr[j + 1]
            while q < stop and indices[q] < i:     # lower entries of row j without a partner
                c = indices[q]
                w = abs(data[q])
                diff[j] += w
                diff[c] += w
                q += 1
            if q < stop and indices[q] == i:
                d = abs(v - data[q])
                diff[i] += d
                diff[j] += d
                q += 1
            else:
                w = abs(v)
                diff[i] += w
                diff[j] += w
            ptr[j] = q
        if row > mx:
            mx = row
    for j in range(n):       # lower entries never reached by a partner
        q = ptr[j]
        while q < indptr[j + 1] and indices[q] < j:
            w = abs(data[q])
            diff[j] += w
            diff[indices[q]] += w
            q += 1
    worst = 0.0
    for i in range(n):
        if diff[i] > worst:
            worst = diff[i]
    return worst, mx
