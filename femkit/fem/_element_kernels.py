"""Compiled (numba) passes of the element-generic assembly (P2 and any dof map): the CSR pattern
built row by row from the dof map, the stiffness, the quadrature points of a load and the load. Serial,
cached on disk (``cache=True``), imported only when a large mesh asks for them
(:data:`femkit.fem.sparsity.NUMBA_THRESHOLD`).

The pattern pass (:func:`_element_pattern`) differs from the P1 builder
(:func:`femkit.fem._kernels._pattern_cells`) in what an incidence carries: the P1 builder copies
every cell's ``w`` vertices into each of its ``w`` incidences ((w m, w) entries, written at
random, read twice); here an incidence is only ``w e + a`` (cell ``e``, local dof ``a``) and the
cell's dofs are read from the dof map when its row is built and the slots written (``w m``
incidence entries instead of ``w^2 m``: P2 has 6 or 10 dofs per cell). The same rows and slots,
entry for entry (tests/fem/test_p2_compiled_passes.py).

A mesh's first stiffness (:func:`first_stiffness`, no pattern cached yet) is summed in such a row
pass (:func:`_stiffness_rows`), from each cell's metric computed once before it (the ``d (d + 1) /
2`` products ``kappa |T| grad lambda_a . grad lambda_b`` of the vertices ``a, b >= 1``,
:func:`_cell_metric`, against a reference tensor folded for them, :func:`metric_table`: 3
products per row entry on a triangle, 6 on a tetrahedron): each incidence adds its cell's local
row into the row being built, whose vertex and edge columns are sorted apart at its end, so no
slot map is written or read (72 MB on a 1M-dof square) and the matrix owns the new index arrays
(no copy of a cached pattern's); the values are the separate pass's bit for bit.
"""

from __future__ import annotations

import numba
import numpy as np

from ..mesh._edges_kernel import sort_pairs
from ._kernels import _cell_gradients, _element_scale, _insert_sorted, _vertex_starts
from .cells.kernels import _tetrahedron, _triangle


@numba.njit(cache=True)
def _element_pattern(cells, n, indices, slots):  # pragma: no cover - compiled
    """CSR pattern of the dof map ``cells`` (m, w) among ``n`` dofs into ``indices`` (a buffer of
    at least ``n + w (w - 1) m`` entries) and ``slots`` (m, w * w). Returns ``(indptr, nnz)``,
    ``indptr`` of the slots' integer type. Compiled with ``w`` a constant for P2 (6 and 10 dofs:
    the loops over a cell's dofs unrolled)."""
    if cells.shape[1] == 6:
        return _pattern_rows(cells, n, indices, slots, 6)
    if cells.shape[1] == 10:
        return _pattern_rows(cells, n, indices, slots, 10)
    return _pattern_rows(cells, n, indices, slots, cells.shape[1])


@numba.njit(cache=True, inline="always")
def _incidence_lists(cells, n, w, like):  # pragma: no cover - compiled
    """The dof -> incidence lists of ``cells`` (a counting sort): ``inc[start[i]:start[i + 1]]``
    holds ``w e + a`` for each cell ``e`` whose local dof ``a`` is ``i``, ``e`` increasing
    (``inc`` of ``like``'s integer type)."""
    m = cells.shape[0]
    start = _vertex_starts(cells, n)
    inc = np.empty(w * m, like.dtype)
    fill = start[:-1].copy()
    for e in range(m):
        for a in range(w):
            i = cells[e, a]
            inc[fill[i]] = w * e + a
            fill[i] += 1
    return start, inc


@numba.njit(cache=True, inline="always")
def _pattern_rows(cells, n, indices, slots, w):  # pragma: no cover - compiled
    """The body of :func:`_element_pattern` for ``w`` dofs per cell."""
    start, inc = _incidence_lists(cells, n, w, slots)
    indptr = np.zeros(n + 1, slots.dtype)
    stamp = np.full(n, -1, slots.dtype)
    pos = np.empty(n, slots.dtype)
    nnz = 0
    for i in range(n):
        s = nnz
        for k in range(start[i], start[i + 1]):
            e = inc[k] // w
            for b in range(w):
                j = cells[e, b]
                if stamp[j] != i:
                    stamp[j] = i
                    nnz = _insert_sorted(indices, s, nnz, j)
        for q in range(s, nnz):
            pos[indices[q]] = q
        for k in range(start[i], start[i + 1]):
            e = inc[k] // w
            a = inc[k] - w * e
            for b in range(w):
                slots[e, w * a + b] = pos[cells[e, b]]
        indptr[i + 1] = nnz
    return indptr, nnz


@numba.njit(cache=True)
def _stiffness_rows(cells, n, split, indices, k, table, data):  # pragma: no cover - compiled
    """The CSR pattern (as :func:`_element_pattern`, no slots) and the stiffness values of the dof
    map ``cells`` into ``indices`` and ``data`` (buffers of ``n + w (w - 1) m`` entries), row by
    row: each incidence (cell ``e``, local dof ``a``) of the row adds the cell's local row
    ``sum_p k[e, p] table[a, p, :]`` (``k`` (m, P): the cells' metrics, :func:`_cell_metric`;
    ``table`` (w, P, w): the folded reference tensor, :func:`metric_table`; p in order, as
    :func:`_element_stiffness` sums it) at its columns, appended when new; the row is then sorted
    with its values. Columns below ``split`` (the vertex dofs, which number below every edge dof)
    and the others are gathered and sorted apart, then joined: two short sorts instead of one
    of their sum's length. Each entry sums its cells in increasing ``e`` (the incidences'
    order), as the separate pass does: the same bits. Returns ``(indptr, nnz)``."""
    if cells.shape[1] == 6:
        return _value_rows(cells, n, split, indices, k, table, data, 6)
    if cells.shape[1] == 10:
        return _value_rows(cells, n, split, indices, k, table, data, 10)
    return _value_rows(cells, n, split, indices, k, table, data, cells.shape[1])


@numba.njit(cache=True, inline="always")
def _value_rows(cells, n, split, indices, k, table, data, w):  # pragma: no cover - compiled
    """The body of :func:`_stiffness_rows` for ``w`` dofs per cell. A row's columns below ``split``
    and the others are gathered, with their sums, in two small buffers (in cache), each sorted,
    then written out. ``mark[j]`` (one array, one read per column) holds ``(row << 32) |
    position in its buffer`` of column ``j``'s last row."""
    start, inc = _incidence_lists(cells, n, w, indices)
    indptr = np.zeros(n + 1, indices.dtype)
    mark = np.full(n, -1, np.int64)
    most = 0
    for i in range(n):
        most = max(most, start[i + 1] - start[i])
    low, low_data = np.empty(w * most, indices.dtype), np.empty(w * most)
    high, high_data = np.empty(w * most, indices.dtype), np.empty(w * most)
    row = np.zeros(w)
    nnz = 0
    for i in range(n):
        key = np.int64(i) << 32
        nl = 0
        nh = 0
        for q in range(start[i], start[i + 1]):
            e = inc[q] // w
            _local_row(k, table, e, inc[q] - w * e, row, w)
            for b in range(w):
                j = cells[e, b]
                mk = mark[j]
                if mk >> 32 == i:             # met before in this row: add
                    if j < split:
                        low_data[mk & 0xFFFFFFFF] += row[b]
                    else:
                        high_data[mk & 0xFFFFFFFF] += row[b]
                elif j < split:
                    mark[j] = key | nl
                    low[nl] = j
                    low_data[nl] = 0.0
                    low_data[nl] += row[b]
                    nl += 1
                else:
                    mark[j] = key | nh
                    high[nh] = j
                    high_data[nh] = 0.0
                    high_data[nh] += row[b]
                    nh += 1
        sort_pairs(low, low_data, 0, nl)
        sort_pairs(high, high_data, 0, nh)
        for q in range(nl):
            indices[nnz + q] = low[q]
            data[nnz + q] = low_data[q]
        nnz += nl
        for q in range(nh):
            indices[nnz + q] = high[q]
            data[nnz + q] = high_data[q]
        nnz += nh
        indptr[i + 1] = nnz
    return indptr, nnz


@numba.njit(cache=True, inline="always")
def _local_row(k, table, e, a, row, w):  # pragma: no cover - compiled
    """Row ``a`` of cell ``e``'s stiffness into ``row``: ``sum_p k[e, p] table[a, p, :]``."""
    for b in range(w):
        row[b] = 0.0
    for p in range(k.shape[1]):
        c = k[e, p]
        for b in range(w):
            row[b] += c * table[a, p, b]


@numba.njit(cache=True)
def _cell_metric(cells, points, kappa, scalar_kappa):  # pragma: no cover - compiled
    """The symmetric metric of every cell, ``k_ab = kappa |T| grad lambda_a . grad lambda_b`` for
    the vertices ``1 <= a <= b <= d`` (row by row: 3 products on a triangle, 6 on a tetrahedron;
    ``lambda_0 = 1 - sum`` needs none of its own), (m, P), and the number of degenerate cells
    (their rows zero). A triangle's from its edges (``e_a`` opposite vertex ``a``:
    ``k_ab = kappa e_a . e_b / (4 |T|)``), a tetrahedron's from its scaled face normals."""
    m = cells.shape[0]
    if points.shape[1] == 2:
        k = np.zeros((m, 3))
        bad = 0
        for e in range(m):
            _, _, _, _, _, ex1, ey1, ex2, ey2, area = _triangle(cells, points, e)
            ok, s = _element_scale(area, 4.0, kappa, scalar_kappa, e)
            if not ok:
                bad += 1
                continue
            k[e, 0] = s * (ex1 * ex1 + ey1 * ey1)
            k[e, 1] = s * (ex1 * ex2 + ey1 * ey2)
            k[e, 2] = s * (ex2 * ex2 + ey2 * ey2)
        return k, bad
    k = np.zeros((m, 6))
    g = np.zeros((4, 3))
    bad = 0
    for e in range(m):
        ok, s = _cell_gradients(cells, points, e, 4, kappa, scalar_kappa, g)
        if not ok:
            bad += 1
            continue
        p = 0
        for a in range(1, 4):
            for b in range(a, 4):
                k[e, p] = s * (g[a, 0] * g[b, 0] + g[a, 1] * g[b, 1] + g[a, 2] * g[b, 2])
                p += 1
    return k, bad


def cell_metric(mesh, kappa) -> np.ndarray | None:
    """The cells' symmetric metrics (m, P) (:func:`_cell_metric`) for ``kappa`` (a float or one
    per cell); None if a cell is degenerate."""
    from ._kernels import _values

    k, bad = _cell_metric(np.ascontiguousarray(mesh.cells, dtype=np.int64),
                          np.ascontiguousarray(mesh.points, dtype=np.float64), *_values(kappa))
    return None if bad else k


def _pattern_buffers(cells: np.ndarray, n: int, *, with_slots: bool = True):
    """``cells`` as int64, the ``indices`` buffer and the ``slots`` of :func:`_element_pattern`
    (int32 when the entry count allows it; ``slots`` without rows unless ``with_slots``)."""
    cells = np.ascontiguousarray(cells, dtype=np.int64)
    m, w = cells.shape
    bound = int(n) + w * (w - 1) * m
    dtype = np.int32 if max(bound, w * m) < np.iinfo(np.int32).max else np.int64
    return cells, np.empty(bound, dtype), np.empty((m if with_slots else 0, w * w), dtype)


def element_pattern_kernel(cells: np.ndarray, n: int):
    """``(indptr, indices, slots)`` of the dof map ``cells`` among ``n`` dofs (compiled,
    :func:`_element_pattern`); ``indices`` and ``slots`` int32 when the entry count allows it."""
    cells, indices, slots = _pattern_buffers(cells, n)
    indptr, nnz = _element_pattern(cells, int(n), indices, slots)
    indices.resize(nnz, refcheck=False)   # shrink in place: the untouched tail was never paged in
    return indptr, indices, slots


def first_stiffness(mesh, dofs, kappa, table: np.ndarray):
    """The stiffness matrix (CSR, sorted rows) of the dof map ``dofs`` on ``mesh`` for the
    reference tensor ``table`` ((d+1)^2, n^2), pattern and values in one pass and no slot map
    (:func:`_stiffness_rows`): the first assembly on a large mesh. ``kappa``: a float or one per
    cell. None if a cell is degenerate (the caller's numpy path then names it)."""
    import scipy.sparse as sp

    k = cell_metric(mesh, kappa)
    if k is None:
        return None
    cells, indices, _ = _pattern_buffers(dofs.cells, dofs.n_dofs, with_slots=False)
    data = np.empty(len(indices))
    w = cells.shape[1]
    folded = metric_table(table, mesh.dim + 1).reshape(-1, w, w)           # (P, a, b)
    folded = np.ascontiguousarray(folded.transpose(1, 0, 2))                # (a, P, b)
    split = int(getattr(dofs, "n_vertices", dofs.n_dofs))
    indptr, nnz = _stiffness_rows(cells, int(dofs.n_dofs), split, indices, k, folded, data)
    indices.resize(nnz, refcheck=False)   # shrink in place: the untouched tails were never paged in
    data.resize(nnz, refcheck=False)
    K = sp.csr_matrix((data, indices, indptr), shape=(dofs.n_dofs, dofs.n_dofs), copy=False)
    K.has_sorted_indices = True
    return K


@numba.njit(cache=True)
def _quadrature_coordinates(cells, points, bary):  # pragma: no cover - compiled
    """(d, m, q) coordinates of the barycentric points ``bary`` (q, d + 1) on each cell (its
    first d + 1 columns the vertices), summed vertex by vertex in order (compiled with the
    vertex count a constant: 3, 4)."""
    if bary.shape[1] == 3:
        return _coordinates(cells, points, bary, 3)
    if bary.shape[1] == 4:
        return _coordinates(cells, points, bary, 4)
    return _coordinates(cells, points, bary, bary.shape[1])


@numba.njit(cache=True, inline="always")
def _coordinates(cells, points, bary, nv):  # pragma: no cover - compiled
    """The body of :func:`_quadrature_coordinates` for ``nv`` vertices per cell."""
    m = cells.shape[0]
    d = points.shape[1]
    nq = bary.shape[0]
    out = np.empty((d, m, nq))
    x = np.empty(nv)                        # one coordinate of the cell's vertices, read once
    for e in range(m):
        for c in range(d):
            for a in range(nv):
                x[a] = points[cells[e, a], c]
            for p in range(nq):
                acc = x[0] * bary[p, 0]
                for a in range(1, nv):
                    acc += x[a] * bary[p, a]
                out[c, e, p] = acc
    return out


@numba.njit(cache=True)
def _element_load(cells, points, fq, wphi, F):  # pragma: no cover - compiled
    """``F_i += sum_cells |T| sum_q fq[e, q] wphi[q, a]`` over the dof map ``cells`` (m, w) (a
    block of cells); returns the number of degenerate cells (compiled with ``w`` a constant for
    P2: 6, 10)."""
    if cells.shape[1] == 6:
        return _load_cells(cells, points, fq, wphi, F, 6)
    if cells.shape[1] == 10:
        return _load_cells(cells, points, fq, wphi, F, 10)
    return _load_cells(cells, points, fq, wphi, F, cells.shape[1])


@numba.njit(cache=True, inline="always")
def _load_cells(cells, points, fq, wphi, F, w):  # pragma: no cover - compiled
    """The body of :func:`_element_load` for ``w`` dofs per cell."""
    m = cells.shape[0]
    nq = wphi.shape[0]
    g = np.zeros((4, 3))
    bad = 0
    for e in range(m):
        if points.shape[1] == 2:
            measure = _triangle(cells, points, e)[9]
        else:
            measure = abs(_tetrahedron(cells, points, e, g)) / 6.0
        if not (measure > 0.0 and measure < np.inf):
            bad += 1
            continue
        for a in range(w):
            acc = 0.0
            for p in range(nq):
                acc += fq[e, p] * wphi[p, a]
            F[cells[e, a]] += measure * acc
    return bad


def quadrature_coordinates(cells: np.ndarray, points: np.ndarray, bary: np.ndarray) -> tuple:
    """``d`` arrays (m, q): the physical coordinates of the rule's points ``bary`` on each cell."""
    return tuple(_quadrature_coordinates(np.ascontiguousarray(cells, dtype=np.int64),
                                         np.ascontiguousarray(points, dtype=np.float64),
                                         np.ascontiguousarray(bary, dtype=np.float64)))


def element_load_kernel(cells: np.ndarray, points: np.ndarray, fq: np.ndarray, wphi: np.ndarray,
                        F: np.ndarray) -> bool:
    """Add the load of the cells ``cells`` (rows of a dof map) from ``f`` at their quadrature
    points ``fq`` (m, q) and ``wphi[q, a] = w_q phi_a(x_q)`` into ``F`` (n_dofs,); False (``F``
    partly summed) if a cell is degenerate."""
    bad = _element_load(np.ascontiguousarray(cells, dtype=np.int64),
                        np.ascontiguousarray(points, dtype=np.float64),
                        np.ascontiguousarray(fq, dtype=np.float64),
                        np.ascontiguousarray(wphi, dtype=np.float64), F)
    return not bad


def warm_up() -> None:
    """Compile (or load from the on-disk cache) these kernels with a large run's argument types
    (a P2 triangle and a P2 tetrahedron)."""
    from types import SimpleNamespace

    from ..elements import get_element

    for dim in (2, 3):
        nv = dim + 1
        pts = np.vstack([np.zeros(dim), np.eye(dim)])
        elem = get_element("P2", dim)
        w = elem.n_dofs
        cells = np.arange(w, dtype=np.int64)[None, :]   # one cell; only its vertices are read as points
        element_pattern_kernel(cells, w)
        first_stiffness(SimpleNamespace(cells=cells[:, :nv], points=pts, dim=dim),
                        SimpleNamespace(cells=cells, n_dofs=w), 1.0, np.ones(((dim + 1) ** 2, w * w)))
        k, _ = _cell_metric(cells, pts, np.ones(1), True)
        _element_stiffness(k, np.ones((k.shape[1], w * w)), np.arange(w * w, dtype=np.int32).reshape(1, -1),
                           w * w)
        quadrature_coordinates(cells, pts, np.full((1, nv), 1.0 / nv))
        fq = np.ones((1, 1))
        element_load_kernel(cells, pts, fq, np.ones((1, w)), np.zeros(w))          # a compiled source's values
        element_load_kernel(cells, pts, np.broadcast_to(fq, (1, 1)), np.ones((1, w)), np.zeros(w))  # NumPy's (read-only)


@numba.njit(cache=True)
def _element_stiffness(metric, table, slots, nnz):  # pragma: no cover - compiled
    """Stiffness of an element other than P1 on affine cells into CSR data: per cell its metric
    ``metric`` (the ``1 <= a <= b`` products of :func:`_cell_metric`; ``table`` row ``p`` for
    pair ``p``, :func:`metric_table`), then ``local += metric_ab table[p]`` row by row (independent sums
    over the ``w^2`` entries, which the compiler vectorises), then scattered through ``slots``."""
    m, npair = metric.shape
    n2 = table.shape[1]
    data = np.zeros(nnz)
    local = np.empty(n2)
    for e in range(m):
        for j in range(n2):
            local[j] = 0.0
        for p in range(npair):
            k = metric[e, p]
            for j in range(n2):
                local[j] += k * table[p, j]
        for j in range(n2):
            data[slots[e, j]] += local[j]
    return data


def metric_table(table: np.ndarray, nv: int) -> np.ndarray:
    """The reference tensor ``table`` ((nv^2, n^2), row ``nv a + b``: ``S_ab``) folded for the cell
    metric of :func:`_cell_metric`: with ``grad lambda_0 = -sum_a grad lambda_a``, ``sum_ab G_ab
    S_ab = sum_{1 <= a, b} G_ab T_ab``, ``T_ab = S_ab - S_a0 - S_0b + S_00``; row ``p`` of pair
    ``1 <= a <= b`` is ``T_ab + T_ba`` (``T_aa`` on the diagonal), each made exactly symmetric in
    its two dof indices (so is every local matrix, and the global one). (P, n^2)."""
    S = np.asarray(table, dtype=np.float64).reshape(nv, nv, -1)
    n = int(round(np.sqrt(S.shape[2])))
    T = S - S[:, :1] - S[:1, :] + S[:1, :1]
    rows = [T[a, a] if a == b else T[a, b] + T[b, a] for a in range(1, nv) for b in range(a, nv)]
    R = np.array(rows).reshape(-1, n, n)
    return np.ascontiguousarray((0.5 * (R + R.transpose(0, 2, 1))).reshape(len(rows), -1))


def element_stiffness_kernel(mesh, kappa, table: np.ndarray, pattern):
    """CSR data of the stiffness of every cell of ``mesh`` for the reference tensor ``table``
    ((d+1)^2, n^2) into ``pattern``, or None if a cell is degenerate (the caller's numpy path
    then names it). ``kappa``: a float or one per cell."""
    k = cell_metric(mesh, kappa)
    if k is None:
        return None
    return _element_stiffness(k, metric_table(table, mesh.dim + 1), pattern.slots, pattern.nnz)
