"""Compiled (numba) one-off assembly of the P1 stiffness of triangles and tetrahedra.

What ``femkit solve`` calls (``keep_pattern=False``; imported only for large meshes): the
stiffness as CSR without the (m, 9) / (m, 16) slot map and the vertex copies of the
element-order pattern pass (:func:`femkit.fem._kernels._pattern`, ``_pattern_cells``). Two
passes (:func:`_cell_rows`, then :func:`_triangle_values` or :func:`_tet_values`) and a sort of
each row:

1. rows, node by node from a node -> element incidence list (counting sort): each row's columns
   in the order they are met, appended to one buffer (no pass that counts the rows first), and
   for each element and vertex ``a`` the positions of its other ``w - 1`` vertices in row
   ``cells[e, a]`` as bytes (``rel``, (m, w (w - 1)) uint8: 6 bytes per triangle, 12 per
   tetrahedron, a third of an int32 slot map), with each row's own diagonal position
   (``diag``, one byte per node);
2. values, element by element: each element's geometry once (the row-wise kernels this replaced
   computed it once per vertex) and its local entries added at ``indptr[row] + position``;
3. each row's (column, value) pairs sorted by column (insertion sort, rows are short:
   :func:`femkit.mesh._edges_kernel.sort_buckets`).

A mesh whose edges are known already (red refinement derives the fine mesh's from the coarse
mesh's, :func:`femkit.mesh.edges.remember_edges`) takes a shorter route with no search and no sort
(:func:`_edge_pattern`, :func:`_edge_values`, :func:`_edge_fill`): in the edges' lexicographic
order the rows come out sorted, so their positions are known before any value, each element's
entries are added at the diagonal and upper positions, and each edge's value is then copied
to its lower entry.

Every entry is the same products (``kappa (e_a . e_b) / (4 |T|)`` on a triangle, ``kappa (g_a .
g_b) / (6 |D|)`` on a tetrahedron) summed over its elements in increasing element order, as the
element-order pass sums them: the matrix is :func:`~femkit.fem._kernels._pattern` /
``_stiffness``'s (``_pattern_cells`` / ``_stiffness_tet``'s) bit for bit (tests/fem/test_rows3d.py,
tests/fem/test_one_off.py). Memory besides the matrix: the incidences (w m int32) and ``rel``
while the rows are built, ``rel`` alone while the values are summed. The column buffer is
reserved at its bound (n + w (w - 1) m entries) and shrunk to the entry count: only the pages
written are ever resident. A row with more than 255 columns does not fit a byte: the caller then
takes the element-order pass.
"""

from __future__ import annotations

import numba
import numpy as np

from ..mesh._edges_kernel import sort_buckets
from ._kernels import _element_scale, _incidences, _values
from .cells.kernels import _tetrahedron, _triangle

#: Row positions are stored in one byte: rows longer than this take the element-order pass.
MAX_ROW = 255


@numba.njit(cache=True)
def _cell_rows(cells, n, inc, start, indices, rel, diag):  # pragma: no cover - compiled
    """Pass 1: the columns of every row in the order met (``indices``, appended), ``rel[e, (w -
    1) a + c]`` the position in row ``cells[e, a]`` of the ``c``-th other vertex of ``e`` (``w``
    vertices per cell), ``diag[i]`` the position of ``i`` in its row. Returns ``(indptr, nnz,
    fits)``; ``fits`` is False (and the rest incomplete) when a row has more than
    :data:`MAX_ROW` columns."""
    w = cells.shape[1]
    indptr = np.zeros(n + 1, np.int64)
    mark = np.full(n, -1, np.int64)  # (row << 8) | position of the column in that row
    q = 0
    for i in range(n):
        s = q
        tag = np.int64(i) << 8
        for k in range(start[i], start[i + 1]):
            e = inc[k]
            a = 0
            while cells[e, a] != i:
                a += 1
            c = (w - 1) * a
            for b in range(w):
                j = cells[e, b]
                mj = mark[j]
                if (mj >> 8) != i:
                    if q - s == MAX_ROW:
                        return indptr, q, False
                    mj = tag | (q - s)
                    mark[j] = mj
                    indices[q] = j
                    q += 1
                if b != a:
                    rel[e, c] = mj & 255
                    c += 1
        diag[i] = mark[i] & 255
        indptr[i + 1] = q
    return indptr, q, True


@numba.njit(cache=True)
def _triangle_values(tri, points, kappa, scalar_kappa, indptr, rel, diag, nnz):  # pragma: no cover - compiled
    """Pass 2 on triangles: each element's ``kappa (e_a . e_b) / (4 |T|)`` (the edge vectors of
    :func:`~femkit.fem.cells.kernels._triangle`, once per element) added at the positions of pass 1,
    in element order. Returns ``(data, bad)`` as :func:`_tet_values`."""
    data = np.zeros(nnz)
    bad = 0
    for e in range(tri.shape[0]):
        i0, i1, i2, ex0, ey0, ex1, ey1, ex2, ey2, area = _triangle(tri, points, e)
        ok, sc = _element_scale(area, 4.0, kappa, scalar_kappa, e)
        if not ok:
            bad += 1
            continue
        d01 = sc * (ex0 * ex1 + ey0 * ey1)
        d02 = sc * (ex0 * ex2 + ey0 * ey2)
        d12 = sc * (ex1 * ex2 + ey1 * ey2)
        b0, b1, b2 = indptr[i0], indptr[i1], indptr[i2]
        data[b0 + diag[i0]] += sc * (ex0 * ex0 + ey0 * ey0)
        data[b0 + rel[e, 0]] += d01
        data[b0 + rel[e, 1]] += d02
        data[b1 + rel[e, 2]] += d01
        data[b1 + diag[i1]] += sc * (ex1 * ex1 + ey1 * ey1)
        data[b1 + rel[e, 3]] += d12
        data[b2 + rel[e, 4]] += d02
        data[b2 + rel[e, 5]] += d12
        data[b2 + diag[i2]] += sc * (ex2 * ex2 + ey2 * ey2)
    return data, bad


@numba.njit(cache=True)
def _tet_values(tets, points, kappa, scalar_kappa, indptr, rel, diag, nnz):  # pragma: no cover - compiled
    """Pass 2: each element's ``kappa (g_a . g_b) / (6 |D|)`` (``g = D grad N``, the geometry of
    :func:`~femkit.fem.cells.kernels._tetrahedron`, once per element) added at the positions of pass
    1, in element order. Returns ``(data, bad)``, ``bad`` the number of degenerate
    tetrahedra (then ``data`` is incomplete)."""
    data = np.zeros(nnz)
    g = np.empty((4, 3))
    bad = 0
    for e in range(tets.shape[0]):
        ok, sc = _element_scale(abs(_tetrahedron(tets, points, e, g)), 6.0, kappa, scalar_kappa, e)
        if not ok:
            bad += 1
            continue
        for a in range(4):
            i = tets[e, a]
            base = indptr[i]
            c = 3 * a
            for b in range(4):
                v = sc * (g[a, 0] * g[b, 0] + g[a, 1] * g[b, 1] + g[a, 2] * g[b, 2])
                if b == a:
                    data[base + diag[i]] += v
                else:
                    data[base + rel[e, c]] += v
                    c += 1
    return data, bad


@numba.njit(cache=True)
def _edge_pattern(edge_nodes, n, index_type):  # pragma: no cover - compiled
    """The CSR rows of the P1 matrix of the edges ``edge_nodes`` (sorted lexicographically,
    ``lo < hi``) over ``n`` nodes. Row ``i``: the lower ends of its edges to lower nodes
    (ascending: they are met in edge order), ``i``, the higher ends of its own edges
    (consecutive and ascending in edge order): sorted with no sort. A node in no edge (in no
    cell) has an empty row, as the incidence rows give it.

    Returns ``(indptr, indices, diag, shift)``: ``indices`` with the diagonal written (the rest
    by :func:`_edge_fill`), ``diag[i]`` the position of ``(i, i)`` and ``shift[i]`` that of
    ``(i, hi)`` minus the id of its edge, so edge ``e`` of lower node ``lo`` sits at
    ``shift[lo] + e`` (``indptr`` and ``indices`` of ``index_type``'s dtype)."""
    diag = np.zeros(n, np.int64)    # the number of edges to lower nodes, then the position
    shift = np.zeros(n, np.int64)   # the number of edges to higher nodes, then the shift
    for e in range(edge_nodes.shape[0]):
        shift[edge_nodes[e, 0]] += 1
        diag[edge_nodes[e, 1]] += 1
    indptr = np.empty(n + 1, index_type.dtype)
    indptr[0] = 0
    q = 0                           # the end of the rows so far
    first = 0                       # the first edge whose lower node is i
    for i in range(n):
        lower, upper = diag[i], shift[i]
        d = q + lower
        diag[i] = d
        shift[i] = d + 1 - first
        first += upper
        if lower + upper > 0:
            q = d + 1 + upper
        indptr[i + 1] = q
    indices = np.empty(q, index_type.dtype)
    for i in range(n):
        if indptr[i + 1] > indptr[i]:
            indices[diag[i]] = i
    return indptr, indices, diag, shift


@numba.njit(cache=True)
def _edge_values(cells, points, kappa, scalar_kappa, cell_edges, local, diag, shift, nnz):  # pragma: no cover - compiled
    """Pass 2 from the edges: each element's entries (the products of :func:`_triangle_values`
    / :func:`_tet_values`, the same floats) added in element order at the positions of
    :func:`_edge_pattern`: ``(i, i)`` at ``diag[i]``, the upper entry of the edge
    ``cell_edges[e, k]`` (joining the local vertices ``local[k]``, the lower of the two nodes
    ``lo``) at ``shift[lo] + cell_edges[e, k]``.
    Returns ``(data, bad)``, ``bad`` the number of degenerate cells (then ``data`` is
    incomplete); the lower entries are copied by :func:`_edge_fill`."""
    m, w = cells.shape
    data = np.zeros(nnz)
    bad = 0
    if w == 3:  # edge k is opposite vertex k
        for e in range(m):
            i0, i1, i2, ex0, ey0, ex1, ey1, ex2, ey2, area = _triangle(cells, points, e)
            ok, sc = _element_scale(area, 4.0, kappa, scalar_kappa, e)
            if not ok:
                bad += 1
                continue
            data[diag[i0]] += sc * (ex0 * ex0 + ey0 * ey0)
            data[diag[i1]] += sc * (ex1 * ex1 + ey1 * ey1)
            data[diag[i2]] += sc * (ex2 * ex2 + ey2 * ey2)
            # the edge opposite vertex 2 joins i0 and i1: its lower node is the smaller
            data[shift[min(i0, i1)] + cell_edges[e, 2]] += sc * (ex0 * ex1 + ey0 * ey1)
            data[shift[min(i0, i2)] + cell_edges[e, 1]] += sc * (ex0 * ex2 + ey0 * ey2)
            data[shift[min(i1, i2)] + cell_edges[e, 0]] += sc * (ex1 * ex2 + ey1 * ey2)
        return data, bad
    g = np.empty((4, 3))
    for e in range(m):
        ok, sc = _element_scale(abs(_tetrahedron(cells, points, e, g)), 6.0, kappa, scalar_kappa, e)
        if not ok:
            bad += 1
            continue
        for a in range(4):
            data[diag[cells[e, a]]] += sc * (g[a, 0] * g[a, 0] + g[a, 1] * g[a, 1] + g[a, 2] * g[a, 2])
        for k in range(local.shape[0]):
            a, b = local[k, 0], local[k, 1]
            lo = min(cells[e, a], cells[e, b])
            data[shift[lo] + cell_edges[e, k]] += sc * (g[a, 0] * g[b, 0] + g[a, 1] * g[b, 1]
                                                        + g[a, 2] * g[b, 2])
    return data, bad


@numba.njit(cache=True)
def _edge_fill(edge_nodes, indptr, indices, data, shift):  # pragma: no cover - compiled
    """The off-diagonal columns of :func:`_edge_pattern`'s rows, and each edge's upper value
    copied to its lower entry ``(hi, lo)``: the lower entries of row ``hi`` in edge order."""
    fill = np.empty(indptr.shape[0] - 1, np.int64)
    for i in range(fill.shape[0]):
        fill[i] = indptr[i]
    for e in range(edge_nodes.shape[0]):
        lo, hi = edge_nodes[e, 0], edge_nodes[e, 1]
        p = shift[lo] + e
        indices[p] = hi
        q = fill[hi]
        fill[hi] = q + 1
        indices[q] = lo
        data[q] = data[p]


def _rows_from_edges(mesh, cells, kappa, known, index):
    """``(indptr, indices, data)`` from the mesh's known edges, or None (a degenerate cell)."""
    from ..mesh.mesh import LOCAL_EDGES

    edge_nodes, cell_edges = known
    w = cells.shape[1]
    indptr, indices, diag, shift = _edge_pattern(edge_nodes, mesh.n_points, np.empty(0, index))
    data, bad = _edge_values(cells, mesh.points, *_values(kappa), cell_edges,
                             LOCAL_EDGES[w].astype(np.int64), diag, shift, len(indices))
    del diag
    if bad:
        return None
    _edge_fill(edge_nodes, indptr, indices, data, shift)
    return indptr, indices, data


def stiffness_rows_kernel(mesh, kappa):
    """``(indptr, indices, data)`` of the stiffness of a whole triangle or tetrahedral mesh
    (passes 1-3 of the module's docstring), or None if some cell is degenerate or some row has
    more than :data:`MAX_ROW` columns (the caller then takes the element-order pass, which says
    which cells are degenerate); ``kappa`` a float or one value per element. From the mesh's
    edges when they are known (:func:`femkit.mesh.edges.known_edges`): the same matrix."""
    m, n = mesh.n_cells, mesh.n_points
    w = mesh.cells.shape[1]
    pairs = w * (w - 1)
    index = np.int32 if max(w * m, n + pairs * m) < np.iinfo(np.int32).max else np.int64
    cells = np.ascontiguousarray(mesh.cells, dtype=np.int64)
    from ..mesh.edges import known_edges

    known = known_edges(mesh)
    if known is not None:
        return _rows_from_edges(mesh, cells, kappa, known, index)
    inc = np.empty(w * m, index)
    start = _incidences(cells, n, inc)
    indices = np.empty(n + pairs * m, index)  # the bound; pages past the entries are never touched
    rel = np.empty((m, pairs), np.uint8)
    diag = np.empty(n, np.uint8)
    indptr, nnz, fits = _cell_rows(cells, n, inc, start, indices, rel, diag)
    del inc, start
    if not fits:
        return None
    indices.resize(nnz, refcheck=False)     # shrinks in place (no copy)
    values = _triangle_values if w == 3 else _tet_values
    data, bad = values(cells, mesh.points, *_values(kappa), indptr, rel, diag, nnz)
    del rel
    if bad:
        return None
    sort_buckets(indptr, indices, data)     # each row's (column, value) pairs by column
    return indptr, indices, data


def warm_up(dims: tuple[int, ...] = (2, 3)) -> None:
    """Compile (or load from the on-disk cache) the kernels of this module on one triangle and
    (``3 in dims``) one tetrahedron, with the argument types of a large mesh (int64 cells, int32
    incidences, edges and columns): the incidence rows (a mesh read from a file), then the
    route from the edges (a refined mesh)."""
    from ..mesh import Mesh
    from ..mesh.edges import edges

    p2 = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    p3 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    meshes = [Mesh(p2, np.array([[0, 1, 2]], dtype=np.int64))]
    if 3 in dims:
        meshes.append(Mesh(p3, np.array([[0, 1, 2, 3]], dtype=np.int64)))
    for mesh in meshes:
        stiffness_rows_kernel(mesh, 1.0)
        stiffness_rows_kernel(mesh, np.ones(1))
        edges(mesh)                          # now known: the route from the edges
        stiffness_rows_kernel(mesh, 1.0)
        stiffness_rows_kernel(mesh, np.ones(1))
