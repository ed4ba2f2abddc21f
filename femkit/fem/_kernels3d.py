"""Compiled (numba) row-wise assembly of P1 tetrahedra; imported only for large meshes.

The tetrahedron counterpart of :func:`femkit.fem._kernels._stiffness_rows`: the stiffness as
CSR built row by row from a node -> element incidence list, without the (m, 16) slot map and
the (4 m, 4) vertex copies of the element-order pattern pass (5.3M tetrahedra: 0.68 GB of int32
buffers fewer, and the memory traffic that made the pattern ~80 % of a first assembly).
"""

from __future__ import annotations

import numba
import numpy as np

from ._kernels import _row_columns, _row_lengths, _tetrahedron, _values


@numba.njit(cache=True)
def _stiffness_rows_tet(tets, n, points, kappa, scalar_kappa, inc):  # pragma: no cover - compiled
    """The P1 stiffness of tetrahedra as CSR, row by row: ``(indptr, indices, data, bad)``.

    ``inc`` is the ``4 m`` buffer of the node -> element incidences (counting sort: elements in
    increasing order around each node); ``indices`` get its dtype. Row ``i`` is the sorted set
    of the vertices of its elements; each element adds its local row ``a`` (``i`` = its vertex
    ``a``): ``kappa (g_a . g_b) / (6 |D|)`` with ``g = D grad N`` from the same
    :func:`~femkit.fem._kernels._tetrahedron` as the element-order kernels, so every entry is
    the same products summed over its elements in increasing element order: bit for bit the
    matrix of :func:`~femkit.fem._kernels._pattern_cells` / ``_stiffness_tet``. Each element's
    geometry is computed once per vertex (4 times) instead of read back from a slot map.
    ``bad`` counts degenerate tetrahedra (then ``data`` is incomplete).
    """
    start, indptr, stamp = _row_lengths(tets, n, inc)
    nnz = indptr[n]
    indices = np.empty(nnz, inc.dtype)
    data = np.zeros(nnz)
    pos = np.empty(n, np.int64)
    g = np.empty((4, 3))
    bad = 0
    # pass 2: sorted columns (insertion sort: rows are short, ~15), then the local rows summed
    for i in range(n):
        _row_columns(tets, inc, start[i], start[i + 1], i, stamp, indices, indptr[i], True, pos)
        for k in range(start[i], start[i + 1]):
            e = inc[k]
            vol6 = abs(_tetrahedron(tets, points, e, g))
            if not (vol6 > 0.0 and vol6 < np.inf):
                bad += 1
                continue
            sc = (kappa[0] if scalar_kappa else kappa[e]) / (6.0 * vol6)
            a = 0
            while tets[e, a] != i:
                a += 1
            for b in range(4):
                data[pos[tets[e, b]]] += sc * (g[a, 0] * g[b, 0] + g[a, 1] * g[b, 1] + g[a, 2] * g[b, 2])
    return indptr, indices, data, bad


def stiffness_rows_tet_kernel(mesh, kappa):
    """``(indptr, indices, data)`` of the stiffness of a whole tetrahedral mesh built row by row
    (:func:`_stiffness_rows_tet`), or None if some tetrahedron is degenerate; ``kappa`` a float
    or one value per element."""
    m, n = mesh.n_cells, mesh.n_points
    inc = np.empty(4 * m, np.int32 if max(4 * m, 27 * n) < np.iinfo(np.int32).max else np.int64)
    tets = np.ascontiguousarray(mesh.cells, dtype=np.int64)
    indptr, indices, data, bad = _stiffness_rows_tet(tets, n, mesh.points, *_values(kappa), inc)
    return None if bad else (indptr, indices, data)


def warm_up() -> None:
    """Compile (or load from the on-disk cache) the kernels of this module on one tetrahedron."""
    tet = np.array([[0, 1, 2, 3]], dtype=np.int64)
    p3 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    _stiffness_rows_tet(tet, 4, p3, np.ones(1), True, np.empty(4, np.int32))
