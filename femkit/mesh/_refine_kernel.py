"""Compiled (numba) passes of red refinement of triangles and tetrahedra (:func:`femkit.mesh.refine`).

Used from :data:`femkit.mesh.refine.NUMBA_THRESHOLD` triangles on; they write the arrays
the NumPy path builds with ``np.stack`` (children, midpoints), element by element, without
its (m, 3) temporaries. Compiled once and cached on disk (``cache=True``), serial.
"""

from __future__ import annotations

import numba
import numpy as np

from ._edges_kernel import sort_buckets


@numba.njit(cache=True)
def red_children(tri, tri_edges, n):  # pragma: no cover - compiled
    """The four children of every triangle, ``(4 m, 3)``: ``(v0, m2, m1)``, ``(m2, v1, m0)``,
    ``(m1, m0, v2)``, ``(m0, m1, m2)`` with ``mk = n + tri_edges[t, k]`` (the midpoint of the
    edge opposite vertex k); counter-clockwise when the parent is."""
    m = tri.shape[0]
    out = np.empty((4 * m, 3), np.int64)
    for t in range(m):
        v0, v1, v2 = tri[t, 0], tri[t, 1], tri[t, 2]
        m0, m1, m2 = n + tri_edges[t, 0], n + tri_edges[t, 1], n + tri_edges[t, 2]
        c = 4 * t
        out[c, 0], out[c, 1], out[c, 2] = v0, m2, m1
        out[c + 1, 0], out[c + 1, 1], out[c + 1, 2] = m2, v1, m0
        out[c + 2, 0], out[c + 2, 1], out[c + 2, 2] = m1, m0, v2
        out[c + 3, 0], out[c + 3, 1], out[c + 3, 2] = m0, m1, m2
    return out


@numba.njit(cache=True)
def with_midpoints(points, edge_nodes):  # pragma: no cover - compiled
    """``points`` followed by the midpoint of every edge (``(a + b) / 2``, as ``mean`` rounds)."""
    n, d = points.shape
    out = np.empty((n + edge_nodes.shape[0], d))
    out[:n] = points
    for e in range(edge_nodes.shape[0]):
        a, b = edge_nodes[e, 0], edge_nodes[e, 1]
        for k in range(d):
            out[n + e, k] = (points[a, k] + points[b, k]) / 2.0
    return out


@numba.njit(cache=True)
def child_edges(n, edge_nodes, tri, tri_edges):  # pragma: no cover - compiled
    """The edges of the red refinement :func:`red_children` makes, from the coarse mesh's:
    ``(edge_nodes, cell_edges)`` of the fine mesh, the arrays
    :func:`femkit.mesh.edges.edges` would find on it by a search (sorted node pairs in
    lexicographic order; ``cell_edges[c, k]`` the edge opposite local vertex ``k`` of child
    ``c``).

    A fine edge is either half of a coarse edge ``e``, ``(a, n + e)`` with ``a`` one of its
    nodes, or joins two midpoints of a coarse triangle, ``(n + p, n + q)`` with ``p < q``. The
    halves come first (their lower node is a coarse node), grouped by that node and ordered by
    ``e`` within the group: a counting sort of the coarse edges' ends in edge order. The
    midpoint edges follow, ordered by ``(p, q)``: a counting sort by ``p`` (a bucket holds the
    at most two pairs of each triangle on edge ``p``), then an insertion sort by ``q``. O(E + m)
    with no comparison sort of all keys; two triangles giving the same pair (duplicate
    triangles) share one edge, as in the search.
    """
    n_edges = edge_nodes.shape[0]
    m = tri.shape[0]
    # halves: bucket of coarse node a = the coarse edges at a, in edge order
    start = np.zeros(n + 1, np.int64)
    for e in range(n_edges):
        start[edge_nodes[e, 0] + 1] += 1
        start[edge_nodes[e, 1] + 1] += 1
    for v in range(n):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    half = np.empty((n_edges, 2), np.int64)      # fine edge of (edge_nodes[e, j], n + e)
    n_half = 2 * n_edges
    out_pairs = np.empty((n_half, 2), np.int64)
    for e in range(n_edges):
        for j in range(2):
            a = edge_nodes[e, j]
            q = fill[a]
            fill[a] = q + 1
            half[e, j] = q
            out_pairs[q, 0] = a
            out_pairs[q, 1] = n + e
    # midpoint edges: three per triangle, bucketed by their lower coarse edge
    bstart = np.zeros(n_edges + 1, np.int64)
    for t in range(m):
        for j in range(3):
            p, q = tri_edges[t, (j + 1) % 3], tri_edges[t, (j + 2) % 3]
            bstart[min(p, q) + 1] += 1
    for e in range(n_edges):
        bstart[e + 1] += bstart[e]
    bfill = bstart[:-1].copy()
    b_hi = np.empty(3 * m, np.int64)
    b_id = np.empty(3 * m, np.int64)             # 3 t + j: the pair opposite midpoint j of t
    for t in range(m):
        for j in range(3):
            p, q = tri_edges[t, (j + 1) % 3], tri_edges[t, (j + 2) % 3]
            lo = min(p, q)
            r = bfill[lo]
            bfill[lo] = r + 1
            b_hi[r] = max(p, q)
            b_id[r] = 3 * t + j
    mid = np.empty(3 * m, np.int64)              # fine edge of pair 3 t + j
    count = sort_buckets(bstart, b_hi, b_id)     # each bucket by q; distinct pairs
    edge_out = np.empty((n_half + count, 2), np.int64)
    edge_out[:n_half] = out_pairs
    count = n_half
    for e in range(n_edges):
        s, u = bstart[e], bstart[e + 1]
        for a in range(s, u):
            if a == s or b_hi[a] != b_hi[a - 1]:
                edge_out[count, 0] = n + e
                edge_out[count, 1] = n + b_hi[a]
                count += 1
            mid[b_id[a]] = count - 1
    # the children of red_children: (v0, m2, m1), (m2, v1, m0), (m1, m0, v2), (m0, m1, m2)
    cells = np.empty((4 * m, 3), np.int64)
    for t in range(m):
        c = 4 * t
        for k in range(3):                       # the halves at vertex k: of edges k+1, k+2
            v = tri[t, k]
            e1, e2 = tri_edges[t, (k + 1) % 3], tri_edges[t, (k + 2) % 3]
            # edge k+1 joins v to vertex k+2, edge k+2 to vertex k+1: v is its lower node or not
            h1 = half[e1, 0] if v < tri[t, (k + 2) % 3] else half[e1, 1]
            h2 = half[e2, 0] if v < tri[t, (k + 1) % 3] else half[e2, 1]
            # child k holds v at local k and the pair of the two midpoints opposite it; the
            # half opposite midpoint m_j lies on the other edge at v
            if k == 0:      # (v0, m2, m1): opposite m2 the half of e1, opposite m1 of e2
                cells[c, 0], cells[c, 1], cells[c, 2] = mid[3 * t], h1, h2
            elif k == 1:    # (m2, v1, m0): opposite m2 the half of e0, opposite m0 of e2
                cells[c + 1, 0], cells[c + 1, 1], cells[c + 1, 2] = h2, mid[3 * t + 1], h1
            else:           # (m1, m0, v2): opposite m1 the half of e0, opposite m0 of e1
                cells[c + 2, 0], cells[c + 2, 1], cells[c + 2, 2] = h1, h2, mid[3 * t + 2]
        cells[c + 3, 0], cells[c + 3, 1], cells[c + 3, 2] = mid[3 * t], mid[3 * t + 1], mid[3 * t + 2]
    return edge_out, cells


@numba.njit(cache=True)
def red_tetrahedra(points, cells, cell_edges, n, corners, inner, diagonals):  # pragma: no cover - compiled
    """Bey's eight children of every tetrahedron, ``(8 m, 4)``, as
    :func:`femkit.mesh.refine._refine_tetrahedra` builds them with NumPy (the same array).

    ``points`` already holds the midpoints (:func:`with_midpoints`); local vertex ``4 + k`` of
    a tetrahedron is the midpoint ``n + cell_edges[t, k]``. ``corners`` (4, 4), ``inner``
    (3, 4, 4) and ``diagonals`` (3, 2) are the tables of that module. The inner octahedron is
    cut along its shortest diagonal, a tie (within a relative 1e-10) going to the diagonal most
    aligned with (1, 1, 1), the first on equal terms; a negatively oriented child has its last
    two vertices swapped. The floats compared are formed as the NumPy path forms them.
    """
    m = cells.shape[0]
    out = np.empty((8 * m, 4), np.int64)
    loc = np.empty(10, np.int64)
    len2 = np.empty(3)
    align = np.empty(3)
    for t in range(m):
        for k in range(4):
            loc[k] = cells[t, k]
        for k in range(6):
            loc[4 + k] = n + cell_edges[t, k]
        for k in range(3):
            a, b = loc[diagonals[k, 0]], loc[diagonals[k, 1]]
            d0, d1, d2 = points[a, 0] - points[b, 0], points[a, 1] - points[b, 1], points[a, 2] - points[b, 2]
            len2[k] = (d0 * d0 + d2 * d2) + d1 * d1  # einsum's order over three terms
            align[k] = abs(d0 + d1 + d2) / np.sqrt(len2[k])
        bound = min(len2[0], min(len2[1], len2[2])) * (1.0 + 1e-10)
        choice, best = 0, -np.inf  # np.argmax: the first maximum, or the first NaN
        for k in range(3):
            score = align[k] if len2[k] <= bound else -1.0
            if best != best:
                break
            if score != score or score > best or k == 0:
                choice, best = k, score
        c = 8 * t
        for j in range(4):
            for k in range(4):
                out[c + j, k] = loc[corners[j, k]]
                out[c + 4 + j, k] = loc[inner[choice, j, k]]
        for j in range(8):
            i0, i1, i2, i3 = out[c + j, 0], out[c + j, 1], out[c + j, 2], out[c + j, 3]
            a0, a1, a2 = points[i1, 0] - points[i0, 0], points[i1, 1] - points[i0, 1], points[i1, 2] - points[i0, 2]
            b0, b1, b2 = points[i2, 0] - points[i0, 0], points[i2, 1] - points[i0, 1], points[i2, 2] - points[i0, 2]
            e0, e1, e2 = points[i3, 0] - points[i0, 0], points[i3, 1] - points[i0, 1], points[i3, 2] - points[i0, 2]
            det = (a0 * (b1 * e2 - b2 * e1) + a2 * (b0 * e1 - b1 * e0)) + a1 * (b2 * e0 - b0 * e2)
            if det / 6.0 < 0:
                out[c + j, 2], out[c + j, 3] = i3, i2
    return out


def warm_up() -> None:
    """Compile (or load from the on-disk cache) the kernels."""
    tri = np.array([[0, 1, 2]], np.int64)
    red_children(tri, np.array([[0, 1, 2]], np.int64), 3)
    with_midpoints(np.zeros((3, 2)), np.array([[0, 1]], np.int64))
    child_edges(3, np.array([[0, 1], [0, 2], [1, 2]], np.int64), tri,
                np.array([[2, 1, 0]], np.int64))
    from .refine import _CORNERS, _DIAGONALS, _INNER

    red_tetrahedra(np.zeros((10, 3)), np.array([[0, 1, 2, 3]], np.int64),
                   np.arange(6, dtype=np.int32)[None, :], 4, _CORNERS, _INNER, _DIAGONALS)
