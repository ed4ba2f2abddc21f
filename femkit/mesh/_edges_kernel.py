"""Compiled (numba) unique-edge kernel behind :func:`femkit.mesh.edges.edges` on large meshes.

Imported only when a mesh has at least :data:`femkit.mesh.edges.NUMBA_THRESHOLD` cells; compiled
once and cached on disk (``cache=True``), serial like every femkit kernel.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def cell_edges(cells, local, n, node_type, edge_type):  # pragma: no cover - compiled
    """Unique edges of ``cells`` in lexicographic order and the edge of each local edge.

    ``node_type`` and ``edge_type`` (empty arrays) give the integer types of the two outputs
    (int32 where the ids fit: :func:`femkit.mesh.edges.index_dtype`).
    ``local`` (k, 2) lists the local edges of a cell (:data:`femkit.mesh.mesh.LOCAL_EDGES`).
    Reads ``cells`` directly (no (m, k, 2) copy, no separate min / max arrays): a counting sort
    of the m k local edges by their lower node (O(m k), no comparison sort of the keys), each
    entry one int64 ``hi << 32 | e k + j`` (one write per local edge, one array to sort: the
    caller keeps ``m k < 2^32``), then an insertion sort inside each bucket (a node has ~6 edges
    in 2D, ~14 in 3D): by the higher node, and among equal ones by the local edge's number, the
    order they were filled in (so it is the stable sort by the higher node).
    Returns ``(edge_nodes (E, 2), cell_edges (m, k))``, the same arrays as
    ``np.unique(lo * n + hi, return_inverse=True)`` gives.
    """
    m = cells.shape[0]
    k = local.shape[0]
    start = np.zeros(n + 1, np.int64)
    for e in range(m):
        for j in range(k):
            a, b = cells[e, local[j, 0]], cells[e, local[j, 1]]
            start[min(a, b) + 1] += 1
    for v in range(n):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    bucket = np.empty(m * k, np.int64)
    for e in range(m):
        for j in range(k):
            a, b = cells[e, local[j, 0]], cells[e, local[j, 1]]
            q = fill[min(a, b)]
            fill[min(a, b)] = q + 1
            bucket[q] = (np.int64(max(a, b)) << 32) | (e * k + j)
    count = sort_keys(start, bucket, 32)
    edge_nodes = np.empty((count, 2), node_type.dtype)  # exactly sized: no (m k, 2) buffer
    inverse = np.empty((m, k), edge_type.dtype)
    count = 0
    for v in range(n):
        for a in range(start[v], start[v + 1]):
            hi = bucket[a] >> 32
            if a == start[v] or hi != bucket[a - 1] >> 32:
                edge_nodes[count, 0] = v
                edge_nodes[count, 1] = hi
                count += 1
            i = bucket[a] & 0xFFFFFFFF
            inverse[i // k, i % k] = count - 1
    return edge_nodes, inverse


@numba.njit(cache=True)
def sort_buckets(start, key, ident):  # pragma: no cover - compiled
    """Sort each bucket ``key[start[v]:start[v + 1]]`` (carrying ``ident`` along) by insertion
    (buckets are short); returns the number of distinct keys over all buckets."""
    count = 0
    for v in range(start.shape[0] - 1):
        s, t = start[v], start[v + 1]
        sort_pairs(key, ident, s, t)
        for a in range(s, t):
            if a == s or key[a] != key[a - 1]:
                count += 1
    return count


@numba.njit(cache=True, inline="always")
def sort_keys(start, key, shift):  # pragma: no cover - compiled
    """Sort each bucket ``key[start[v]:start[v + 1]]`` by insertion (buckets are short); returns
    the number of distinct ``key >> shift`` over all buckets (``shift = 0``: distinct keys)."""
    count = 0
    for v in range(start.shape[0] - 1):
        s, t = start[v], start[v + 1]
        for a in range(s + 1, t):
            h = key[a]
            b = a
            while b > s and key[b - 1] > h:
                key[b] = key[b - 1]
                b -= 1
            key[b] = h
        for a in range(s, t):
            if a == s or key[a] >> shift != key[a - 1] >> shift:
                count += 1
    return count


@numba.njit(cache=True, inline="always")
def sort_pairs(key, ident, s, t):  # pragma: no cover - compiled
    """Insertion sort of ``key[s:t]`` with ``ident[s:t]`` along (runs are short)."""
    for a in range(s + 1, t):
        h, i = key[a], ident[a]
        b = a
        while b > s and key[b - 1] > h:
            key[b] = key[b - 1]
            ident[b] = ident[b - 1]
            b -= 1
        key[b] = h
        ident[b] = i


def warm_up() -> None:
    """Compile (or load from the on-disk cache) the kernel for triangles and tetrahedra."""
    from .mesh import LOCAL_EDGES

    for cells in (np.array([[0, 1, 2], [0, 2, 3]], np.int64), np.array([[0, 1, 2, 3]], np.int64)):
        cell_edges(cells, LOCAL_EDGES[cells.shape[1]], 4, np.zeros(0, np.int32),
                   np.zeros(0, np.int32))
