"""Compiled (numba) passes of red refinement of triangles and tetrahedra (:func:`femkit.mesh.refine`).

Used from :data:`femkit.mesh.refine.NUMBA_THRESHOLD` triangles on; they write the arrays
the NumPy path builds with ``np.stack`` (children, midpoints), element by element, without
its (m, 3) temporaries. Compiled once and cached on disk (``cache=True``), serial.
"""

from __future__ import annotations

import numba
import numpy as np

from ._edges_kernel import sort_buckets, sort_keys


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


@numba.njit(cache=True, inline="always")
def pair_starts(tri_edges, n_edges, extra):  # pragma: no cover - compiled
    """Bucket starts (``n_edges + 1``) of the midpoint pairs of the triangles, three per
    triangle, bucketed by their lower coarse edge, after ``extra`` entries per bucket."""
    bstart = np.zeros(n_edges + 1, np.int64)
    for e in range(n_edges):
        bstart[e + 1] += extra
    for t in range(tri_edges.shape[0]):
        for j in range(3):
            p, q = tri_edges[t, (j + 1) % 3], tri_edges[t, (j + 2) % 3]
            bstart[min(p, q) + 1] += 1
    for e in range(n_edges):
        bstart[e + 1] += bstart[e]
    return bstart


@numba.njit(cache=True, inline="always")
def bucket_pairs(tri_edges, bfill, b_hi, b_id, inv, n):  # pragma: no cover - compiled
    """Put the pair ``(p, q)``, ``p < q``, of midpoints of each triangle ``t`` other than that
    of its edge ``j`` in bucket ``p`` (next free slot ``bfill[p]``): key ``q`` (``inv[n + q]``
    when ``inv`` is not empty: the new id of the midpoint), id ``3 t + j`` (unless ``b_id`` is
    empty)."""
    for t in range(tri_edges.shape[0]):
        for j in range(3):
            p, q = tri_edges[t, (j + 1) % 3], tri_edges[t, (j + 2) % 3]
            lo = min(p, q)
            r = bfill[lo]
            bfill[lo] = r + 1
            b_hi[r] = max(p, q) if inv.shape[0] == 0 else inv[n + max(p, q)]
            if b_id.shape[0] > 0:
                b_id[r] = 3 * t + j


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
    bstart = pair_starts(tri_edges, n_edges, 0)
    bfill = bstart[:-1].copy()
    b_hi = np.empty(3 * m, np.int64)
    b_id = np.empty(3 * m, np.int64)             # 3 t + j: the pair opposite midpoint j of t
    bucket_pairs(tri_edges, bfill, b_hi, b_id, np.zeros(0, np.int64), 0)
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
        child_cell_edges(cells, t, tri, tri_edges, half, mid)
    return edge_out, cells


@numba.njit(cache=True, inline="always")
def child_cell_edges(cells, t, tri, tri_edges, half, mid):  # pragma: no cover - compiled
    """Rows ``4 t .. 4 t + 3`` of the fine ``cell_edges`` (the children of :func:`red_children`)
    from ``half[e, j]``, the fine edge joining node ``j`` of coarse edge ``e`` to its midpoint,
    and ``mid[3 t + j]``, the fine edge joining the two midpoints of triangle ``t`` other than
    that of its edge ``j``."""
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


@numba.njit(cache=True)
def interleaved_red(points, tri, edge_nodes, tri_edges, local, node_type, edge_type):  # pragma: no cover - compiled
    """Red refinement of triangles straight into the interleaved numbering of
    :func:`femkit.mesh.hierarchy.interleave_permutation` (every coarse node followed by the
    midpoints of its edges to higher nodes), with the fine mesh's edges in that numbering.

    Returns ``(points, children, inv, fine_edges, fine_cell_edges)``: what
    :func:`with_midpoints`, :func:`red_children` and :func:`child_edges` give, renumbered by
    ``inv`` (old fine id -> new: coarse node ``v`` -> ``v + below[v]``, midpoint of edge ``e``
    -> ``lo(e) + 1 + e``, ``below[v]`` the number of edges whose lower node is below ``v``), and
    the edges :func:`femkit.mesh.edges.edges` would find on the renumbered mesh, in one pass
    with no sort of the nodes or of the edges: in the new numbering a coarse node's edges to
    its midpoints come first and in edge order (the first halves), and each midpoint's bucket
    holds the second half of its edge and the pairs of midpoints with a higher edge id, a few
    entries sorted by insertion.
    """
    n = points.shape[0]
    n_edges = edge_nodes.shape[0]
    m = tri.shape[0]
    below, inv, out_pts = interleave(points, edge_nodes)
    # bucket of midpoint e (by its new id): the second half (e, hi end) and the pairs (e, q > e)
    bstart = pair_starts(tri_edges, n_edges, 1)
    bfill = bstart[:-1].copy()
    b_hi = np.empty(bstart[n_edges], node_type.dtype)   # the new id of the other end
    for e in range(n_edges):
        b_hi[bfill[e]] = inv[edge_nodes[e, 1]]
        bfill[e] += 1
    bucket_pairs(tri_edges, bfill, b_hi, np.empty(0, np.int64), inv, n)  # no ids: not needed
    children = np.empty((4 * m, 3), np.int64)
    for t in range(m):
        v0, v1, v2 = inv[tri[t, 0]], inv[tri[t, 1]], inv[tri[t, 2]]
        m0, m1, m2 = inv[n + tri_edges[t, 0]], inv[n + tri_edges[t, 1]], inv[n + tri_edges[t, 2]]
        c = 4 * t
        children[c, 0], children[c, 1], children[c, 2] = v0, m2, m1
        children[c + 1, 0], children[c + 1, 1], children[c + 1, 2] = m2, v1, m0
        children[c + 2, 0], children[c + 2, 1], children[c + 2, 2] = m1, m0, v2
        children[c + 3, 0], children[c + 3, 1], children[c + 3, 2] = m0, m1, m2
    fine_edges, cells = interleaved_edges(n, below, inv, bstart, b_hi, children, local, node_type,
                                          edge_type)
    return out_pts, children, inv, fine_edges, cells


@numba.njit(cache=True, inline="always")
def interleaved_edges(n, below, inv, bstart, b_hi, children, local, node_type, edge_type):  # pragma: no cover - compiled
    """The fine edges of an interleaved refinement and the children's ``cell_edges``:
    ``bstart``/``b_hi`` hold, per coarse edge, the new ids of the other ends of the edges
    from its midpoint to higher nodes (sorted here by insertion, kept once); the first halves
    at a coarse node are its edges' midpoints in order. Each child's local edge ``local[k]``
    is then looked up in the bucket of its lower node (a few entries)."""
    n_edges = bstart.shape[0] - 1
    count = sort_keys(bstart, b_hi, 0)           # each bucket by key, counting distinct keys
    fine_edges = np.empty((n_edges + count, 2), node_type.dtype)
    node_start = np.empty(n + n_edges + 1, np.int64)
    count = 0
    for v in range(n):
        node_start[inv[v]] = count
        for e in range(below[v], below[v + 1]):  # the first halves at v, in edge order
            fine_edges[count, 0] = inv[v]
            fine_edges[count, 1] = inv[n + e]
            count += 1
        for e in range(below[v], below[v + 1]):  # then the buckets of v's midpoints
            node_start[inv[n + e]] = count
            s, u = bstart[e], bstart[e + 1]
            for a in range(s, u):
                if a == s or b_hi[a] != b_hi[a - 1]:
                    fine_edges[count, 0] = inv[n + e]
                    fine_edges[count, 1] = b_hi[a]
                    count += 1
    node_start[n + n_edges] = count
    cells = np.empty((children.shape[0], local.shape[0]), edge_type.dtype)
    for c in range(children.shape[0]):
        for k in range(local.shape[0]):
            x, y = children[c, local[k, 0]], children[c, local[k, 1]]
            lo, hi = min(x, y), max(x, y)
            r = node_start[lo]
            while fine_edges[r, 1] != hi:
                r += 1
            cells[c, k] = r
    return fine_edges, cells


@numba.njit(cache=True)
def interleaved_rows(n_coarse, edge_nodes, inv, index_type):  # pragma: no cover - compiled
    """CSR arrays ``(indptr, indices, data)`` of the P1 prolongation of a red refinement whose
    fine node ``j`` (coarse nodes, then one midpoint per edge) is numbered ``inv[j]``: the row
    of a coarse node ``v`` holds 1 at ``v``, that of the midpoint of edge ``(a, b)`` 1/2 at
    ``a`` and at ``b``."""
    n_edges = edge_nodes.shape[0]
    n_fine = n_coarse + n_edges
    width = np.ones(n_fine, index_type.dtype)
    for e in range(n_edges):
        width[inv[n_coarse + e]] = 2
    indptr = np.empty(n_fine + 1, index_type.dtype)
    indptr[0] = 0
    for r in range(n_fine):
        indptr[r + 1] = indptr[r] + width[r]
    indices = np.empty(n_coarse + 2 * n_edges, index_type.dtype)
    data = np.empty(n_coarse + 2 * n_edges)
    for v in range(n_coarse):
        r = indptr[inv[v]]
        indices[r] = v
        data[r] = 1.0
    for e in range(n_edges):
        r = indptr[inv[n_coarse + e]]
        indices[r], indices[r + 1] = edge_nodes[e, 0], edge_nodes[e, 1]
        data[r], data[r + 1] = 0.5, 0.5
    return indptr, indices, data


@numba.njit(cache=True, error_model="numpy")  # a diagonal of length 0 is NaN, no raise
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
    work = np.empty((2, 3))
    for t in range(m):
        for k in range(4):
            loc[k] = cells[t, k]
        for k in range(6):
            loc[4 + k] = n + cell_edges[t, k]
        bey_children(points, loc, out, 8 * t, corners, inner, diagonals, work)
    return out


@numba.njit(cache=True, error_model="numpy", inline="always")
def bey_children(points, loc, out, c, corners, inner, diagonals, work):  # pragma: no cover - compiled
    """Rows ``c .. c + 7`` of ``out``: the children of the tetrahedron whose local vertices
    (corners, then midpoints) are the nodes ``loc`` (10,) of ``points``; returns the diagonal
    chosen (:func:`red_tetrahedra`). ``work`` (2, 3): scratch."""
    len2, align = work[0], work[1]
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
    return choice




@numba.njit(cache=True, inline="always")
def interleave(points, edge_nodes):  # pragma: no cover - compiled
    """``(below, inv, fine_points)`` of a red refinement in the interleaved numbering: ``below[v]``
    the number of edges whose lower node is below ``v``, ``inv`` old fine id -> new (coarse node
    ``v`` -> ``v + below[v]``, midpoint of edge ``e`` (old id ``n + e``) -> ``lo(e) + 1 + e``),
    and the coarse points and edge midpoints (``(a + b) / 2``) at their new ids."""
    n, d = points.shape
    n_edges = edge_nodes.shape[0]
    below = np.zeros(n + 1, np.int64)
    for e in range(n_edges):
        below[edge_nodes[e, 0] + 1] += 1
    for v in range(n):
        below[v + 1] += below[v]
    inv = np.empty(n + n_edges, np.int64)
    for v in range(n):
        inv[v] = v + below[v]
    for e in range(n_edges):
        inv[n + e] = edge_nodes[e, 0] + 1 + e
    out_pts = np.empty((n + n_edges, d))
    for v in range(n):
        for k in range(d):
            out_pts[inv[v], k] = points[v, k]
    for e in range(n_edges):
        a, b = edge_nodes[e, 0], edge_nodes[e, 1]
        for k in range(d):
            out_pts[inv[n + e], k] = (points[a, k] + points[b, k]) / 2.0
    return below, inv, out_pts


@numba.njit(cache=True)
def interleaved_bey(points, cells, edge_nodes, cell_edges, local, node_type, edge_type,
                    corners, inner, diagonals, face_pairs, diagonal_pairs):  # pragma: no cover - compiled
    """Bey's refinement of tetrahedra straight into the interleaved numbering, with the fine
    mesh's edges in it: :func:`interleaved_red` for tetrahedra. Returns ``(points, children,
    inv, fine_edges, fine_cell_edges)``: :func:`with_midpoints` and :func:`red_tetrahedra`'s
    arrays renumbered by ``inv``, and what :func:`femkit.mesh.edges.edges` would find on the
    result.

    The fine edges are the halves of the coarse edges, the three midpoint pairs of every coarse
    face and the inner diagonal of every tetrahedron. In the new numbering a coarse node's
    first halves come in edge order; each midpoint's bucket holds its edge's second half and
    its pairs with higher midpoints (a face's pairs twice, from its two tetrahedra: kept once),
    sorted by insertion. A child's local edges are then looked up in the bucket of their lower
    node (a few entries).
    """
    n = points.shape[0]
    n_edges = edge_nodes.shape[0]
    m = cells.shape[0]
    below, inv, out_pts = interleave(points, edge_nodes)
    children = np.empty((8 * m, 4), np.int64)
    choice = np.empty(m, np.int64)
    loc = np.empty(10, np.int64)
    work = np.empty((2, 3))
    for t in range(m):
        for k in range(4):
            loc[k] = inv[cells[t, k]]
        for k in range(6):
            loc[4 + k] = inv[n + cell_edges[t, k]]
        choice[t] = bey_children(out_pts, loc, children, 8 * t, corners, inner, diagonals, work)
    n_pairs = face_pairs.shape[0] + 1
    bstart = np.ones(n_edges + 1, np.int64)      # one second half per bucket, then the pairs
    bstart[0] = 0
    for t in range(m):
        for j in range(n_pairs):
            pr = face_pairs[j] if j + 1 < n_pairs else diagonal_pairs[choice[t]]
            p, q = cell_edges[t, pr[0]], cell_edges[t, pr[1]]
            bstart[min(p, q) + 1] += 1
    for e in range(n_edges):
        bstart[e + 1] += bstart[e]
    bfill = bstart[:-1].copy()
    b_hi = np.empty(bstart[n_edges], node_type.dtype)
    for e in range(n_edges):
        b_hi[bfill[e]] = inv[edge_nodes[e, 1]]
        bfill[e] += 1
    for t in range(m):
        for j in range(n_pairs):
            pr = face_pairs[j] if j + 1 < n_pairs else diagonal_pairs[choice[t]]
            p, q = cell_edges[t, pr[0]], cell_edges[t, pr[1]]
            lo = min(p, q)
            b_hi[bfill[lo]] = inv[n + max(p, q)]
            bfill[lo] += 1
    fine_edges, fine_cell_edges = interleaved_edges(n, below, inv, bstart, b_hi, children, local,
                                                    node_type, edge_type)
    return out_pts, children, inv, fine_edges, fine_cell_edges


def warm_up(dims: tuple[int, ...] = (2, 3)) -> None:
    """Compile (or load from the on-disk cache) the kernels of the dimensions ``dims``, with
    the argument types of a run (int64 cells, the 32-bit edge arrays of
    :func:`femkit.mesh.edges.edges`; the interleaved refinements also with the read-only edge
    arrays a mesh keeps, which numba types apart: the hierarchy refines each level with the
    edges the previous refinement left on it)."""
    from .mesh import LOCAL_EDGES

    if 2 in dims:
        tri = np.array([[0, 1, 2]], np.int64)
        edge_nodes = np.array([[0, 1], [0, 2], [1, 2]], np.int32)
        tri_edges = np.array([[2, 1, 0]], np.int32)
        red_children(tri, tri_edges, 3)
        with_midpoints(np.zeros((3, 2)), edge_nodes)
        child_edges(3, edge_nodes, tri, tri_edges)
        for nodes, cell_edges in ((edge_nodes, tri_edges), _read_only(edge_nodes, tri_edges)):
            interleaved_red(np.zeros((3, 2)), tri, nodes, cell_edges, LOCAL_EDGES[3],
                            np.zeros(0, np.int32), np.zeros(0, np.int32))
        interleaved_rows(3, edge_nodes, np.arange(6), np.zeros(0, np.int32))
    if 3 in dims:
        from .bey_tables import CORNERS, DIAGONAL_PAIRS, DIAGONALS, FACE_PAIRS, INNER

        tet = np.array([[0, 1, 2, 3]], np.int64)
        cell_edges = np.arange(6, dtype=np.int32)[None, :]
        tet_edges = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]], np.int32)
        points = np.eye(4, 3)[[3, 0, 1, 2]]
        with_midpoints(points, tet_edges)
        red_tetrahedra(np.vstack([points, points[tet_edges].mean(axis=1)]), tet, cell_edges, 4,
                       CORNERS, INNER, DIAGONALS)
        for nodes, edges_of in ((tet_edges, cell_edges), _read_only(tet_edges, cell_edges)):
            interleaved_bey(points, tet, nodes, edges_of, LOCAL_EDGES[4], np.zeros(0, np.int32),
                            np.zeros(0, np.int32), CORNERS, INNER, DIAGONALS, FACE_PAIRS,
                            DIAGONAL_PAIRS)


def _read_only(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """Read-only copies of ``arrays`` (as :func:`femkit.mesh.edges.remember_edges` keeps them)."""
    out = tuple(a.copy() for a in arrays)
    for a in out:
        a.flags.writeable = False
    return out
