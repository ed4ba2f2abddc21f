"""Compiled (numba) unique-edge kernel behind :func:`femkit.mesh.edges.edges` on large meshes.

Imported only when a mesh has at least :data:`femkit.mesh.edges.NUMBA_THRESHOLD` cells; compiled
once and cached on disk (``cache=True``), serial like every femkit kernel.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def unique_edges(lo, hi, n):  # pragma: no cover - compiled
    """Unique ``(lo, hi)`` pairs in lexicographic order and the position of each input pair.

    A counting sort by ``lo`` (O(N), no comparison sort of the N keys), then an insertion sort
    by ``hi`` inside each ``lo`` bucket (a node has ~6 edges): the same order and inverse as
    ``np.unique(lo * n + hi, return_inverse=True)``.
    """
    k = lo.shape[0]
    start = np.zeros(n + 1, np.int64)
    for i in range(k):
        start[lo[i] + 1] += 1
    for v in range(n):
        start[v + 1] += start[v]
    order = np.empty(k, np.int64)
    fill = start[:-1].copy()
    for i in range(k):
        v = lo[i]
        order[fill[v]] = i
        fill[v] += 1
    edge_lo = np.empty(k, np.int64)
    edge_hi = np.empty(k, np.int64)
    inverse = np.empty(k, np.int64)
    count = 0
    for v in range(n):
        s, e = start[v], start[v + 1]
        for a in range(s + 1, e):  # insertion sort of the bucket by hi
            j = order[a]
            key = hi[j]
            b = a
            while b > s and hi[order[b - 1]] > key:
                order[b] = order[b - 1]
                b -= 1
            order[b] = j
        last = -1
        for a in range(s, e):
            j = order[a]
            if hi[j] != last:
                last = hi[j]
                edge_lo[count] = v
                edge_hi[count] = last
                count += 1
            inverse[j] = count - 1
    return edge_lo[:count], edge_hi[:count], inverse
