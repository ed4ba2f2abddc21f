"""Compiled (numba) unique-face kernel behind :func:`femkit.mesh.faces.faces` on large meshes.

The face counterpart of :mod:`._edges_kernel`: imported only when a mesh has at least
:data:`femkit.mesh.faces.NUMBA_THRESHOLD` tetrahedra, compiled once and cached on disk.
"""

from __future__ import annotations

import numba
import numpy as np

from ._edges_kernel import sort_buckets


@numba.njit(cache=True, inline="always")
def _sorted3(a, b, c):  # pragma: no cover - compiled
    if a > b:
        a, b = b, a
    if b > c:
        b, c = c, b
    if a > b:
        a, b = b, a
    return a, b, c


@numba.njit(cache=True)
def tet_faces(tets, local, n):  # pragma: no cover - compiled
    """Unique faces of ``tets`` in lexicographic order and the face of each local face.

    ``local`` (4, 3) lists the local faces (:data:`femkit.mesh.faces.LOCAL_FACES`). A counting
    sort of the ``4 m`` sorted node triples by their lowest node, then an insertion sort of each
    bucket by ``(middle, highest)`` (a node is the lowest of ~12 faces of a Kuhn mesh). Returns
    ``(face_nodes (F, 3), tet_faces (m, 4))``: the arrays :func:`~femkit.mesh.faces.unique_rows`
    gives for the sorted triples (the same numbering).
    """
    m = tets.shape[0]
    total = 4 * m
    start = np.zeros(n + 1, np.int64)
    for e in range(m):
        for j in range(4):
            a, _, _ = _sorted3(tets[e, local[j, 0]], tets[e, local[j, 1]], tets[e, local[j, 2]])
            start[a + 1] += 1
    for v in range(n):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    key = np.empty(total, np.int64)   # middle * n + highest
    slot = np.empty(total, np.int64)  # 4 e + j
    for e in range(m):
        for j in range(4):
            a, b, c = _sorted3(tets[e, local[j, 0]], tets[e, local[j, 1]], tets[e, local[j, 2]])
            q = fill[a]
            fill[a] = q + 1
            key[q] = b * n + c
            slot[q] = 4 * e + j
    count = sort_buckets(start, key, slot)
    face_nodes = np.empty((count, 3), np.int64)  # exactly sized
    inverse = np.empty((m, 4), np.int64)
    count = 0
    for v in range(n):
        for a in range(start[v], start[v + 1]):
            if a == start[v] or key[a] != key[a - 1]:
                face_nodes[count, 0] = v
                face_nodes[count, 1] = key[a] // n
                face_nodes[count, 2] = key[a] % n
                count += 1
            i = slot[a]
            inverse[i // 4, i % 4] = count - 1
    return face_nodes, inverse
