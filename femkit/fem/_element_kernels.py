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
"""

from __future__ import annotations

import numba
import numpy as np

from ._kernels import _cell_gradients, _insert_sorted, _vertex_starts
from .cells.kernels import _tetrahedron, _triangle


@numba.njit(cache=True)
def _element_pattern(cells, n, indices, slots):  # pragma: no cover - compiled
    """CSR pattern of the dof map ``cells`` (m, w) among ``n`` dofs into ``indices`` (a buffer of
    at least ``n + w (w - 1) m`` entries) and ``slots`` (m, w * w). Returns ``(indptr, nnz)``."""
    m, w = cells.shape
    start = _vertex_starts(cells, n)
    inc = np.empty(w * m, slots.dtype)               # dof -> incidences w e + a, e increasing
    fill = start[:-1].copy()
    for e in range(m):
        for a in range(w):
            i = cells[e, a]
            inc[fill[i]] = w * e + a
            fill[i] += 1
    indptr = np.zeros(n + 1, np.int64)
    stamp = np.full(n, -1, np.int64)
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


def element_pattern_kernel(cells: np.ndarray, n: int):
    """``(indptr, indices, slots)`` of the dof map ``cells`` among ``n`` dofs (compiled,
    :func:`_element_pattern`); ``indices`` and ``slots`` int32 when the entry count allows it."""
    cells = np.ascontiguousarray(cells, dtype=np.int64)
    n = int(n)
    m, w = cells.shape
    bound = n + w * (w - 1) * m
    dtype = np.int32 if max(bound, w * m) < np.iinfo(np.int32).max else np.int64
    indices = np.empty(bound, dtype)
    slots = np.empty((m, w * w), dtype)
    indptr, nnz = _element_pattern(cells, n, indices, slots)
    indices.resize(nnz, refcheck=False)   # shrink in place: the untouched tail was never paged in
    return indptr, indices, slots


@numba.njit(cache=True)
def _quadrature_coordinates(cells, points, bary):  # pragma: no cover - compiled
    """(d, m, q) coordinates of the barycentric points ``bary`` (q, d + 1) on each cell (its
    first d + 1 columns the vertices), summed vertex by vertex in order."""
    m = cells.shape[0]
    d = points.shape[1]
    nq, nv = bary.shape
    out = np.empty((d, m, nq))
    for e in range(m):
        for c in range(d):
            for p in range(nq):
                acc = points[cells[e, 0], c] * bary[p, 0]
                for a in range(1, nv):
                    acc += points[cells[e, a], c] * bary[p, a]
                out[c, e, p] = acc
    return out


@numba.njit(cache=True)
def _element_load(cells, points, fq, wphi, n_dofs):  # pragma: no cover - compiled
    """``F_i = sum_cells |T| sum_q fq[e, q] wphi[q, a]`` over the dof map ``cells`` (m, w);
    returns ``(F, number of degenerate cells)``."""
    m, w = cells.shape
    nq = wphi.shape[0]
    F = np.zeros(n_dofs)
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
    return F, bad


def quadrature_coordinates(cells: np.ndarray, points: np.ndarray, bary: np.ndarray) -> tuple:
    """``d`` arrays (m, q): the physical coordinates of the rule's points ``bary`` on each cell."""
    return tuple(_quadrature_coordinates(np.ascontiguousarray(cells, dtype=np.int64),
                                         np.ascontiguousarray(points, dtype=np.float64),
                                         np.ascontiguousarray(bary, dtype=np.float64)))


def element_load_kernel(cells: np.ndarray, points: np.ndarray, fq: np.ndarray, wphi: np.ndarray,
                        n_dofs: int):
    """The load vector of the dof map ``cells`` from ``f`` at the quadrature points ``fq`` (m, q)
    and ``wphi[q, a] = w_q phi_a(x_q)``; None if a cell is degenerate."""
    F, bad = _element_load(np.ascontiguousarray(cells, dtype=np.int64),
                           np.ascontiguousarray(points, dtype=np.float64),
                           np.ascontiguousarray(fq, dtype=np.float64),
                           np.ascontiguousarray(wphi, dtype=np.float64), int(n_dofs))
    return None if bad else F


def warm_up() -> None:
    """Compile (or load from the on-disk cache) these kernels with a large run's argument types
    (a P2 triangle and a P2 tetrahedron)."""
    from ..elements import get_element

    for dim in (2, 3):
        nv = dim + 1
        pts = np.vstack([np.zeros(dim), np.eye(dim)])
        elem = get_element("P2", dim)
        w = elem.n_dofs
        cells = np.arange(w, dtype=np.int64)[None, :]   # one cell; only its vertices are read as points
        element_pattern_kernel(cells, w)
        _element_stiffness(cells, pts, np.ones(1), True, np.ones(((nv * (nv + 1)) // 2, w * w)),
                           np.arange(w * w, dtype=np.int32).reshape(1, -1), w * w)
        quadrature_coordinates(cells, pts, np.full((1, nv), 1.0 / nv))
        element_load_kernel(cells, pts, np.ones((1, 1)), np.ones((1, w)), w)


@numba.njit(cache=True)
def _element_stiffness(cells, points, kappa, scalar_kappa, table, slots, nnz):  # pragma: no cover - compiled
    """Stiffness of an element other than P1 on affine cells into CSR data: per cell the P1
    products ``k1_ab`` (symmetric: the ``a <= b`` ones, ``table`` row ``p`` for pair ``p`` holding
    ``S_ab + S_ba``, or ``S_aa``), then ``local += k1_ab table[p]`` row by row (independent sums
    over the ``w^2`` entries, which the compiler vectorises; the P1 kernel's order,
    :func:`femkit.fem._kernels._element_stiffness`, sums each entry's products in one chain), then
    scattered through ``slots``. Returns (data, number of degenerate cells)."""
    m = cells.shape[0]
    nv = 3 if points.shape[1] == 2 else 4
    n2 = table.shape[1]
    data = np.zeros(nnz)
    g = np.zeros((4, 3))
    local = np.empty(n2)
    bad = 0
    for e in range(m):
        ok, s = _cell_gradients(cells, points, e, nv, kappa, scalar_kappa, g)
        if not ok:
            bad += 1
            continue
        for j in range(n2):
            local[j] = 0.0
        p = 0
        for a in range(nv):
            for b in range(a, nv):
                k = s * (g[a, 0] * g[b, 0] + g[a, 1] * g[b, 1] + g[a, 2] * g[b, 2])
                for j in range(n2):
                    local[j] += k * table[p, j]
                p += 1
        for j in range(n2):
            data[slots[e, j]] += local[j]
    return data, bad


def symmetric_table(table: np.ndarray, nv: int) -> np.ndarray:
    """The reference tensor ``table`` ((nv^2, n^2), row ``nv a + b``) folded for the symmetric
    P1 products: row ``p`` of pair ``a <= b`` is ``S_ab + S_ba`` (``S_aa`` on the diagonal)."""
    T = np.asarray(table, dtype=np.float64).reshape(nv, nv, -1)
    rows = [T[a, a] if a == b else T[a, b] + T[b, a] for a in range(nv) for b in range(a, nv)]
    return np.ascontiguousarray(np.array(rows))


def element_stiffness_kernel(mesh, kappa, table: np.ndarray, pattern):
    """CSR data of the stiffness of every cell of ``mesh`` for the reference tensor ``table``
    ((d+1)^2, n^2) into ``pattern``, or None if a cell is degenerate (the caller's numpy path
    then names it). ``kappa``: a float or one per cell."""
    from ._kernels import _values

    nv = mesh.dim + 1
    data, bad = _element_stiffness(np.ascontiguousarray(mesh.cells, dtype=np.int64),
                                   np.ascontiguousarray(mesh.points, dtype=np.float64),
                                   *_values(kappa), symmetric_table(table, nv), pattern.slots, pattern.nnz)
    return None if bad else data
