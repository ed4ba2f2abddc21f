"""Compiled (numba) kernels; imported only when a large mesh asks for them.

All kernels are serial (``parallel=False``): the benchmark and CI pin one thread, and the
loops are memory-bound.  They are compiled on first use and cached on disk (``cache=True``).
"""

from __future__ import annotations

import numba
import numpy as np

from .cells.kernels import _tetrahedron, _triangle, _volume6


@numba.njit(cache=True, inline="always")
def _insert_sorted(indices, s, end, j):  # pragma: no cover - compiled
    """Insert column ``j`` into the sorted run ``indices[s:end]`` (insertion sort: rows are
    short); returns the new end."""
    q = end
    while q > s and indices[q - 1] > j:
        indices[q] = indices[q - 1]
        q -= 1
    indices[q] = j
    return end + 1


@numba.njit(cache=True)
def _vertex_starts(cells, n):  # pragma: no cover - compiled
    """Counting sort's offsets of the node -> element incidences: ``start[i]`` = the number of
    cell vertices with a node id below ``i`` (``start[n]`` = all of them)."""
    start = np.zeros(n + 1, np.int64)
    for e in range(cells.shape[0]):
        for a in range(cells.shape[1]):
            start[cells[e, a] + 1] += 1
    for i in range(n):
        start[i + 1] += start[i]
    return start


@numba.njit(cache=True)
def _incidences(cells, n, inc):  # pragma: no cover - compiled
    """The node -> element incidences of ``cells`` (m, w) into ``inc`` (counting sort: elements in
    increasing order around each node); returns ``start``, ``inc[start[i]:start[i + 1]]``
    the elements around node ``i``."""
    start = _vertex_starts(cells, n)
    fill = start[:-1].copy()
    for e in range(cells.shape[0]):
        for a in range(cells.shape[1]):
            i = cells[e, a]
            inc[fill[i]] = e
            fill[i] += 1
    return start


@numba.njit(cache=True)
def _pattern(tri, n, indices, slots, points, kappa, scalar_kappa, with_data):  # pragma: no cover - compiled
    """Node-wise P1 pattern: row i = sorted unique vertices of the elements around node i.

    ``indices`` is a buffer of at least ``n + 6 m`` entries (each element adds at most three
    edges, two entries each); ``slots`` (m, 9) is filled.  With ``with_data`` the stiffness
    (coefficient ``kappa``) is summed in the same element-order pass that writes the slots.
    Returns ``(indptr, nnz, data, number of bad areas)`` (``data`` empty without ``with_data``).

    Node numbers of a mesh are far apart within an element, so node-wise passes over
    ``tri`` would read it at random.  Instead the element's vertices are copied into the
    node -> incidence list while it is built (one sequential read of ``tri``), the rows are
    built from that list sequentially (overwriting each vertex with its CSR position), and
    the slots are gathered back in element order.
    """
    m = tri.shape[0]
    # 1. node -> incidences, by counting sort; each incidence carries the element's vertices.
    start = _vertex_starts(tri, n)
    verts = np.empty((3 * m, 3), slots.dtype)  # incidence k: the three vertices of its element
    where = np.empty(3 * m, slots.dtype)  # 3 e + a -> incidence k
    for e in range(m):
        v0, v1, v2 = tri[e, 0], tri[e, 1], tri[e, 2]
        for a in range(3):
            i = tri[e, a]
            k = start[i]
            start[i] = k + 1
            verts[k, 0] = v0
            verts[k, 1] = v1
            verts[k, 2] = v2
            where[3 * e + a] = k
    for i in range(n, 0, -1):  # start[i] now holds the old start[i + 1]: shift back
        start[i] = start[i - 1]
    start[0] = 0
    # 2. per row: unique neighbours (stamp array), insertion sort (rows are short, ~7), then
    #    each incidence's vertices replaced by the CSR positions of (i, vertex).
    indptr = np.zeros(n + 1, np.int64)
    stamp = np.full(n, -1, np.int64)
    pos = np.empty(n, slots.dtype)
    nnz = 0
    for i in range(n):
        s = nnz
        for k in range(start[i], start[i + 1]):
            for b in range(3):
                j = verts[k, b]
                if stamp[j] != i:
                    stamp[j] = i
                    nnz = _insert_sorted(indices, s, nnz, j)
        for q in range(s, nnz):
            pos[indices[q]] = q
        for k in range(start[i], start[i + 1]):
            for b in range(3):
                verts[k, b] = pos[verts[k, b]]
        indptr[i + 1] = nnz
    # 3. slots in element order: entry (e, a, b) is position b of incidence (e, a); with
    #    with_data the local stiffness goes straight to those positions.
    data = np.zeros(nnz if with_data else 0)
    bad = 0
    for e in range(m):
        for a in range(3):
            k = where[3 * e + a]
            for b in range(3):
                slots[e, 3 * a + b] = verts[k, b]
        if with_data:
            _, _, _, ex0, ey0, ex1, ey1, ex2, ey2, area = _triangle(tri, points, e)
            ok, sc = _element_scale(area, 4.0, kappa, scalar_kappa, e)
            if not ok:
                bad += 1
                continue
            _add_local_stiffness(data, slots, e, sc, ex0, ey0, ex1, ey1, ex2, ey2)
    return indptr, nnz, data, bad


@numba.njit(cache=True)
def _pattern_cells(tri, n, indices, slots, points, kappa, scalar_kappa, with_data):  # pragma: no cover - compiled
    """:func:`_pattern` for cells of any width ``w`` (tetrahedra: 4): the same three passes,
    loops over ``w`` (the triangle kernel keeps its unrolled copies, which are faster). With
    ``with_data`` (tetrahedra) the stiffness is summed in the element-order pass that writes the
    slots, while the element's slots are in cache. Returns ``(indptr, nnz, data, bad)``."""
    m = tri.shape[0]
    w = tri.shape[1]
    # 1. node -> incidences, by counting sort; each incidence carries the element's vertices.
    start = _vertex_starts(tri, n)
    verts = np.empty((w * m, w), slots.dtype)  # incidence k: the w vertices of its element
    where = np.empty(w * m, slots.dtype)  # w e + a -> incidence k
    for e in range(m):
        for a in range(w):
            i = tri[e, a]
            k = start[i]
            start[i] = k + 1
            for b in range(w):
                verts[k, b] = tri[e, b]
            where[w * e + a] = k
    for i in range(n, 0, -1):  # start[i] now holds the old start[i + 1]: shift back
        start[i] = start[i - 1]
    start[0] = 0
    # 2. per row: unique neighbours (stamp array), insertion sort (rows are short, ~7 in 2D,
    #    ~15 in 3D), then each incidence's vertices replaced by the CSR positions of (i, vertex).
    indptr = np.zeros(n + 1, np.int64)
    stamp = np.full(n, -1, np.int64)
    pos = np.empty(n, slots.dtype)
    nnz = 0
    for i in range(n):
        s = nnz
        for k in range(start[i], start[i + 1]):
            for b in range(w):
                j = verts[k, b]
                if stamp[j] != i:
                    stamp[j] = i
                    nnz = _insert_sorted(indices, s, nnz, j)
        for q in range(s, nnz):
            pos[indices[q]] = q
        for k in range(start[i], start[i + 1]):
            for b in range(w):
                verts[k, b] = pos[verts[k, b]]
        indptr[i + 1] = nnz
    # 3. slots in element order: entry (e, a, b) is position b of incidence (e, a)
    data = np.zeros(nnz if with_data else 0)
    g = np.empty((4, 3))
    bad = 0
    for e in range(m):
        for a in range(w):
            k = where[w * e + a]
            for b in range(w):
                slots[e, w * a + b] = verts[k, b]
        if with_data:
            vol6 = abs(_tetrahedron(tri, points, e, g))
            ok, sc = _element_scale(vol6, 6.0, kappa, scalar_kappa, e)
            if not ok:
                bad += 1
                continue
            _add_tet_stiffness(data, slots, e, g, sc)
    return indptr, nnz, data, bad


def pattern_kernel(tri: np.ndarray, n: int, points: np.ndarray | None = None, kappa=None):
    """CSR ``indptr``, ``indices``, the (m, w * w) slot map of the P1 pattern (compiled; ``w``
    = 3 for triangles, 4 for tetrahedra) and, for triangles when ``points`` and ``kappa`` (a
    float or one value per element) are given, the CSR data of the stiffness summed in the
    same pass, for tetrahedra likewise (None if some element is degenerate; else None too when
    not asked).

    ``indices`` and ``slots`` are int32 when the entry count allows it (half the memory
    traffic of int64), else int64.
    """
    tri = np.ascontiguousarray(tri, dtype=np.int64)
    n = int(n)
    m, w = tri.shape
    bound = n + w * (w - 1) * m
    dtype = np.int32 if bound < np.iinfo(np.int32).max else np.int64
    indices = np.empty(bound, dtype)
    slots = np.empty((m, w * w), dtype)
    with_data = points is not None and kappa is not None and w in (3, 4)
    pts = np.ascontiguousarray(points, dtype=np.float64) if with_data else np.zeros((0, w - 1))
    kap, scalar = _values(kappa if with_data else 1.0)
    kernel = _pattern if w == 3 else _pattern_cells
    indptr, nnz, data, bad = kernel(tri, n, indices, slots, pts, kap, scalar, with_data)
    return indptr, indices[:nnz].copy(), slots, (data if with_data and not bad else None)


@numba.njit(cache=True, inline="always")
def _element_scale(measure, d, kappa, scalar_kappa, k):  # pragma: no cover - compiled
    """``(ok, kappa_k / (d * measure))``: the stiffness scale of an element (``d = 4`` and its
    area for a triangle, ``d = 6`` and ``6 |V|`` for a tetrahedron); ``ok`` is False, the element
    degenerate, when ``measure`` is not positive and finite."""
    if not (measure > 0.0 and measure < np.inf):
        return False, 0.0
    return True, (kappa[0] if scalar_kappa else kappa[k]) / (d * measure)


@numba.njit(cache=True)
def _add_local_stiffness(data, slots, e, s, ex0, ey0, ex1, ey1, ex2, ey2):  # pragma: no cover - compiled
    """``data[slots[e, 3 a + b]] += s (e_a . e_b)``: element e's local matrix into CSR data."""
    d01 = s * (ex0 * ex1 + ey0 * ey1)
    d02 = s * (ex0 * ex2 + ey0 * ey2)
    d12 = s * (ex1 * ex2 + ey1 * ey2)
    data[slots[e, 0]] += s * (ex0 * ex0 + ey0 * ey0)
    data[slots[e, 1]] += d01
    data[slots[e, 2]] += d02
    data[slots[e, 3]] += d01
    data[slots[e, 4]] += s * (ex1 * ex1 + ey1 * ey1)
    data[slots[e, 5]] += d12
    data[slots[e, 6]] += d02
    data[slots[e, 7]] += d12
    data[slots[e, 8]] += s * (ex2 * ex2 + ey2 * ey2)


@numba.njit(cache=True)
def _stiffness(tri, points, idx, use_idx, kappa, scalar_kappa, slots, nnz):  # pragma: no cover - compiled
    """Fused local stiffness + scatter into CSR data; returns (data, number of bad areas)."""
    data = np.zeros(nnz)
    count = idx.shape[0] if use_idx else tri.shape[0]
    bad = 0
    for k in range(count):
        e = idx[k] if use_idx else k
        i0, i1, i2, ex0, ey0, ex1, ey1, ex2, ey2, area = _triangle(tri, points, e)
        ok, s = _element_scale(area, 4.0, kappa, scalar_kappa, k)
        if not ok:
            bad += 1
            continue
        _add_local_stiffness(data, slots, e, s, ex0, ey0, ex1, ey1, ex2, ey2)
    return data, bad


def stiffness_kernel(mesh, idx, kappa, pattern):
    """CSR data of the stiffness of elements ``idx`` (None: all; triangles or tetrahedra), or
    None if some element is degenerate (the caller's numpy path then raises with the ids).

    ``kappa`` is a float (the same for every element) or one value per selected element.
    """
    kernel = _stiffness_tet if mesh.dim == 3 else _stiffness
    data, bad = kernel(mesh.cells, mesh.points, *_selection(idx), *_values(kappa), pattern.slots, pattern.nnz)
    return None if bad else data


@numba.njit(cache=True)
def _load_barycentric(tri, points, idx, use_idx, fvals, scalar_f, n):  # pragma: no cover - compiled
    """One-point load ``F_j += |T| f(c) / 3``; returns (F, number of bad areas)."""
    out = np.zeros(n)
    count = idx.shape[0] if use_idx else tri.shape[0]
    bad = 0
    for k in range(count):
        e = idx[k] if use_idx else k
        i0, i1, i2, _, _, _, _, _, _, area = _triangle(tri, points, e)
        if not (area > 0.0 and area < np.inf):
            bad += 1
            continue
        w = area * ((fvals[0] if scalar_f else fvals[k]) / 3.0)
        out[i0] += w
        out[i1] += w
        out[i2] += w
    return out, bad


def load_kernel(mesh, idx, fvals):
    """Barycentric-rule load vector of elements ``idx`` (None: all) with ``fvals`` a float or
    one value of ``f`` per selected element's centroid; None if some element is degenerate."""
    kernel = _load_tet if mesh.dim == 3 else _load_barycentric
    out, bad = kernel(mesh.cells, mesh.points, *_selection(idx), *_values(fvals), mesh.n_points)
    return None if bad else out


@numba.njit(cache=True)
def _stiffness_tet(tets, points, idx, use_idx, kappa, scalar_kappa, slots, nnz):  # pragma: no cover - compiled
    """Fused tetrahedron stiffness ``kappa (g_a . g_b) / (6 |D|)`` + scatter into CSR data
    (``g_a = D grad N_a``); returns (data, number of bad volumes)."""
    data = np.zeros(nnz)
    count = idx.shape[0] if use_idx else tets.shape[0]
    bad = 0
    g = np.empty((4, 3))
    for k in range(count):
        e = idx[k] if use_idx else k
        vol6 = abs(_tetrahedron(tets, points, e, g))
        ok, sc = _element_scale(vol6, 6.0, kappa, scalar_kappa, k)
        if not ok:
            bad += 1
            continue
        _add_tet_stiffness(data, slots, e, g, sc)
    return data, bad


@numba.njit(cache=True, inline="always")
def _add_tet_stiffness(data, slots, e, g, s):  # pragma: no cover - compiled
    """``data[slots[e, 4 a + b]] += s (g_a . g_b)``: element e's local matrix into CSR data."""
    for a in range(4):
        for b in range(a, 4):
            v = s * (g[a, 0] * g[b, 0] + g[a, 1] * g[b, 1] + g[a, 2] * g[b, 2])
            data[slots[e, 4 * a + b]] += v
            if b != a:
                data[slots[e, 4 * b + a]] += v


@numba.njit(cache=True)
def _load_tet(tets, points, idx, use_idx, fvals, scalar_f, n):  # pragma: no cover - compiled
    """One-point load ``F_j += |T| f(c) / 4``; returns (F, number of bad volumes)."""
    out = np.zeros(n)
    count = idx.shape[0] if use_idx else tets.shape[0]
    bad = 0
    for k in range(count):
        e = idx[k] if use_idx else k
        vol = abs(_volume6(tets, points, e)) / 6.0
        if not (vol > 0.0 and vol < np.inf):
            bad += 1
            continue
        w = vol * ((fvals[0] if scalar_f else fvals[k]) / 4.0)
        for a in range(4):
            out[tets[e, a]] += w
    return out, bad


def _selection(idx):
    """Kernel arguments ``(idx array, use_idx)`` for an element subset (None: all)."""
    if idx is None:
        return np.zeros(0, np.int64), False
    return np.ascontiguousarray(idx, dtype=np.int64), True


def _values(values):
    """Kernel arguments ``(float64 array, is_scalar)`` for a scalar or per-element values."""
    return np.ascontiguousarray(np.atleast_1d(np.asarray(values, dtype=np.float64))), np.ndim(values) == 0


def warm_up() -> None:
    """Compile (or load from the on-disk cache) every kernel on a two-triangle mesh."""
    tri = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    ind = np.empty(4 + 12, np.int32)  # int32 slots: every mesh below 2**31 entries
    slots = np.empty((2, 9), np.int32)
    _, nnz, _, _ = _pattern(tri, 4, ind, slots, pts, np.ones(1), True, True)
    _stiffness(tri, pts, np.zeros(1, np.int64), False, np.ones(1), True, slots, nnz)
    _load_barycentric(tri, pts, np.zeros(1, np.int64), False, np.ones(1), True, 4)
    tet = np.array([[0, 1, 2, 3]], dtype=np.int64)
    p3 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    ind3 = np.empty(4 + 12, np.int32)
    slots3 = np.empty((1, 16), np.int32)
    _, nnz3, _, _ = _pattern_cells(tet, 4, ind3, slots3, p3, np.ones(1), True, True)
    _stiffness_tet(tet, p3, np.zeros(1, np.int64), False, np.ones(1), True, slots3, nnz3)
    _load_tet(tet, p3, np.zeros(1, np.int64), False, np.ones(1), True, 4)
    _scatter(np.zeros(nnz3), slots3, np.zeros(1, np.int64), np.ones((1, 16)))
    for cells, pts, slots, nnz_ in ((tri, pts, slots, nnz), (tet, p3, slots3, nnz3)):
        w = cells.shape[1]
        _element_stiffness(cells, pts, np.ones(1), True, np.ones((w * w, w * w)), slots, nnz_)


@numba.njit(cache=True)
def _eliminate(indptr, indices, data, is_fixed, g_full, F, out_indptr, out_indices, out_data, b):  # pragma: no cover - compiled
    """``A = K[free, free]`` and ``b = F[free] - K[free, :] g`` in one pass over ``K``'s rows.

    The entries of the free rows in the free columns are copied in their order (renumbered
    columns), so ``A`` is what SciPy's ``K[free][:, free]`` gives for sorted ``K``; the lifting
    sums ``K_ij g_j`` over the whole row in its order, as SciPy's product does (``g`` is 0 at
    the free nodes). ``out_*`` may be ``K``'s own arrays (the copy only moves entries forward:
    elimination in place). Returns ``nnz(A)``.
    """
    n = is_fixed.shape[0]
    col = np.empty(n, np.int64)
    c = 0
    for j in range(n):
        if is_fixed[j]:
            col[j] = -1
        else:
            col[j] = c
            c += 1
    r = 0
    q = 0
    t = indptr[0]
    out_indptr[0] = 0
    for i in range(n):
        # indptr[i] may be overwritten already (in place): the row starts where the last ended
        s, t = t, indptr[i + 1]
        if is_fixed[i]:
            continue
        acc = 0.0
        for p in range(s, t):
            j = indices[p]
            v = data[p]
            acc += v * g_full[j]
            cj = col[j]
            if cj >= 0:
                out_indices[q] = cj
                out_data[q] = v
                q += 1
        b[r] = F[i] - acc
        r += 1
        out_indptr[r] = q
    return q


def eliminate_kernel(K, F, is_fixed, g_full, overwrite: bool):
    """``(A, b)`` of Dirichlet elimination by :func:`_eliminate`; with ``overwrite`` ``A``
    takes over ``K``'s arrays (``K`` is left invalid)."""
    import scipy.sparse as sp

    n = K.shape[0]
    n_free = n - int(is_fixed.sum())
    if overwrite:
        out_indptr, out_indices, out_data = K.indptr, K.indices, K.data
    else:
        out_indptr = np.empty(n_free + 1, K.indptr.dtype)
        out_indices = np.empty_like(K.indices)
        out_data = np.empty_like(K.data)
    b = np.empty(n_free)
    nnz = _eliminate(K.indptr, K.indices, K.data, is_fixed, g_full, F, out_indptr, out_indices,
                     out_data, b)
    A = sp.csr_matrix((out_data[:nnz], out_indices[:nnz], out_indptr[:n_free + 1]),
                      shape=(n_free, n_free), copy=not overwrite)
    A.has_sorted_indices = True
    return A, b


@numba.njit(cache=True)
def _scatter(data, slots, rows, local):  # pragma: no cover - compiled
    """``data[slots[rows[k], j]] += local[k, j]``: a block of local matrices into CSR data."""
    for k in range(local.shape[0]):
        e = rows[k]
        for j in range(local.shape[1]):
            data[slots[e, j]] += local[k, j]


def scatter_kernel(data: np.ndarray, slots: np.ndarray, rows: np.ndarray, local: np.ndarray) -> None:
    """Add the local matrices ``local`` (k, w * w) of the cells ``rows`` into ``data`` through
    the slot map ``slots`` (m, w * w) (int32, from the compiled pattern builder)."""
    _scatter(data, slots, np.ascontiguousarray(rows, dtype=np.int64),
             np.ascontiguousarray(local, dtype=np.float64))


@numba.njit(cache=True, inline="always")
def _cell_gradients(cells, points, e, nv, kappa, scalar_kappa, g):  # pragma: no cover - compiled
    """The scaled barycentric gradients of cell ``e`` (``nv`` = 3: a triangle, 4: a tetrahedron)
    into ``g`` and ``(ok, scale)`` of :func:`_element_scale`: ``k1_ab = scale g_a . g_b`` is the
    P1 stiffness ``kappa |T| grad lambda_a . grad lambda_b``."""
    if nv == 3:
        _, _, _, ex0, ey0, ex1, ey1, ex2, ey2, area = _triangle(cells, points, e)
        g[0, 0], g[0, 1], g[1, 0], g[1, 1], g[2, 0], g[2, 1] = ex0, ey0, ex1, ey1, ex2, ey2
        return _element_scale(area, 4.0, kappa, scalar_kappa, e)
    vol6 = abs(_tetrahedron(cells, points, e, g))
    return _element_scale(vol6, 6.0, kappa, scalar_kappa, e)


@numba.njit(cache=True)
def _element_stiffness(cells, points, kappa, scalar_kappa, table, slots, nnz):  # pragma: no cover - compiled
    """Stiffness of any Lagrange element on affine cells, summed into CSR data in one pass:
    per cell the P1 matrix ``k1_ab = kappa |T| grad lambda_a . grad lambda_b`` (the same scaled
    edge or face-normal products as :func:`_add_local_stiffness` / :func:`_add_tet_stiffness`),
    then ``local_j = sum_ab k1_ab table[ab, j]`` (``table`` = the reference tensor, ((d+1)^2, n^2))
    scattered through ``slots``. Returns (data, number of degenerate cells)."""
    m, nv = cells.shape
    n2 = table.shape[1]
    data = np.zeros(nnz)
    g = np.zeros((4, 3))
    k1 = np.empty(nv * nv)
    bad = 0
    for e in range(m):
        ok, s = _cell_gradients(cells, points, e, nv, kappa, scalar_kappa, g)
        if not ok:
            bad += 1
            continue
        for a in range(nv):
            for b in range(nv):
                k1[a * nv + b] = s * (g[a, 0] * g[b, 0] + g[a, 1] * g[b, 1] + g[a, 2] * g[b, 2])
        for j in range(n2):
            v = 0.0
            for ab in range(nv * nv):
                v += k1[ab] * table[ab, j]
            data[slots[e, j]] += v
    return data, bad


def element_stiffness_kernel(mesh, kappa, table: np.ndarray, pattern):
    """CSR data of the stiffness of every cell of ``mesh`` for the reference tensor ``table``
    ((d+1)^2, n^2) into ``pattern`` (slots of the element's dofs), or None if a cell is
    degenerate (the caller's numpy path then names it). ``kappa``: a float or one per cell."""
    data, bad = _element_stiffness(np.ascontiguousarray(mesh.cells, dtype=np.int64),
                                   np.ascontiguousarray(mesh.points, dtype=np.float64),
                                   *_values(kappa), np.ascontiguousarray(table, dtype=np.float64),
                                   pattern.slots, pattern.nnz)
    return None if bad else data
