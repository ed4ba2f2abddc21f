"""Compiled (numba) kernels; imported only when a large mesh asks for them."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def _pattern(tri, n):  # pragma: no cover - compiled
    """Edge-based P1 pattern: row i = [lower neighbours] [i] [upper neighbours], sorted."""
    m = tri.shape[0]
    # 1. each element edge (lo, hi) is a candidate in row lo (counting sort by lo).
    start = np.zeros(n + 1, np.int64)
    for e in range(m):
        for a in range(3):
            i, j = tri[e, a], tri[e, (a + 1) % 3]
            start[min(i, j) + 1] += 1
    for i in range(n):
        start[i + 1] += start[i]
    fill = start[:-1].copy()
    cand_col = np.empty(3 * m, np.int64)
    cand_src = np.empty(3 * m, np.int64)  # 3 e + a: edge from vertex a to a+1
    for e in range(m):
        for a in range(3):
            i, j = tri[e, a], tri[e, (a + 1) % 3]
            lo = min(i, j)
            k = fill[lo]
            cand_col[k] = max(i, j)
            cand_src[k] = 3 * e + a
            fill[lo] = k + 1
    # 2. per row: insertion sort of the candidates, de-duplicate -> unique upper neighbours.
    edge_of = np.empty(3 * m, np.int64)  # candidate -> unique edge number
    n_up = np.zeros(n, np.int64)
    n_low = np.zeros(n, np.int64)
    up_start = np.zeros(n + 1, np.int64)
    n_edges = 0
    for i in range(n):
        s, t = start[i], start[i + 1]
        for k in range(s + 1, t):
            c, src = cand_col[k], cand_src[k]
            j = k - 1
            while j >= s and cand_col[j] > c:
                cand_col[j + 1] = cand_col[j]
                cand_src[j + 1] = cand_src[j]
                j -= 1
            cand_col[j + 1] = c
            cand_src[j + 1] = src
        last = -1
        u = -1
        for k in range(s, t):
            c = cand_col[k]
            if c != last:
                u += 1
                last = c
                cand_col[s + u] = c
                n_low[c] += 1
            edge_of[cand_src[k]] = n_edges + u
        n_up[i] = u + 1
        n_edges += u + 1
        up_start[i + 1] = n_edges
    # 3. CSR: row i holds n_low[i] + 1 + n_up[i] entries.
    indptr = np.zeros(n + 1, np.int64)
    for i in range(n):
        indptr[i + 1] = indptr[i] + n_low[i] + 1 + n_up[i]
    indices = np.empty(indptr[n], np.int64)
    slot_up = np.empty(n_edges, np.int64)
    slot_low = np.empty(n_edges, np.int64)
    low_fill = indptr[:-1].copy()
    diag = np.empty(n, np.int64)
    for i in range(n):  # ascending i: lower parts of later rows are filled in sorted order
        d = indptr[i] + n_low[i]
        diag[i] = d
        indices[d] = i
        s = start[i]
        for k in range(n_up[i]):
            j = cand_col[s + k]
            q = up_start[i] + k
            slot_up[q] = d + 1 + k
            indices[d + 1 + k] = j
            slot_low[q] = low_fill[j]
            indices[low_fill[j]] = i
            low_fill[j] += 1
    # 4. element slot map.
    slots = np.empty((m, 9), np.int64)
    for e in range(m):
        for a in range(3):
            slots[e, 4 * a] = diag[tri[e, a]]
        for a in range(3):
            b = (a + 1) % 3
            q = edge_of[3 * e + a]
            if tri[e, a] < tri[e, b]:
                slots[e, 3 * a + b] = slot_up[q]
                slots[e, 3 * b + a] = slot_low[q]
            else:
                slots[e, 3 * a + b] = slot_low[q]
                slots[e, 3 * b + a] = slot_up[q]
    return indptr, indices, slots


def pattern_kernel(tri: np.ndarray, n: int):
    """CSR ``indptr``, ``indices`` and the (m, 9) slot map of the P1 pattern (compiled)."""
    return _pattern(np.ascontiguousarray(tri, dtype=np.int64), int(n))


@numba.njit(cache=True)
def _stiffness(tri, points, idx, kappa, slots, nnz):  # pragma: no cover - compiled
    """Fused local stiffness + scatter into CSR data; returns (data, number of bad areas)."""
    data = np.zeros(nnz)
    ex = np.empty(3)
    ey = np.empty(3)
    bad = 0
    for k in range(idx.shape[0]):
        e = idx[k]
        i0, i1, i2 = tri[e, 0], tri[e, 1], tri[e, 2]
        ex[0] = points[i2, 0] - points[i1, 0]
        ey[0] = points[i2, 1] - points[i1, 1]
        ex[1] = points[i0, 0] - points[i2, 0]
        ey[1] = points[i0, 1] - points[i2, 1]
        ex[2] = points[i1, 0] - points[i0, 0]
        ey[2] = points[i1, 1] - points[i0, 1]
        area = 0.5 * abs(ex[2] * ey[0] - ey[2] * ex[0])
        if not area > 0.0:
            bad += 1
            continue
        s = kappa[k] / (4.0 * area)
        for a in range(3):
            for b in range(3):
                data[slots[e, 3 * a + b]] += s * (ex[a] * ex[b] + ey[a] * ey[b])
    return data, bad


def stiffness_kernel(mesh, idx, kappa, pattern):
    """CSR data of the stiffness of elements ``idx`` (kappa per selected element), or None if
    some triangle is degenerate (the caller's numpy path then raises with the ids)."""
    data, bad = _stiffness(mesh.triangles, mesh.points, idx, np.ascontiguousarray(kappa, dtype=np.float64),
                           pattern.slots, pattern.nnz)
    return None if bad else data
