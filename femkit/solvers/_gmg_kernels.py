"""numba kernels of geometric multigrid (imported lazily by :mod:`.gmg`; imports numba).

V-cycle: matrices are CSR ``(indptr, indices, data)`` of a symmetric matrix with a positive
diagonal. Gauss-Seidel / SOR is written as ``x_i += omega (b_i - sum_j a_ij x_j) / a_ii`` with
``inv_diag = omega / diag(A)`` (the row sum includes the diagonal), so no diagonal-free copy of
``A`` is needed.

Setup: :func:`transpose` (``P^T`` by a counting sort) and :func:`galerkin` (``P^T A P`` row by
row, Gustavson 1978), for any CSR ``A`` and ``P``. :mod:`.gmg` passes int32 index arrays viewed as
uint32 (no negative-index wrap-around test per access: 1.6x faster here) and int64 ones as they are.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def _relax(indptr, indices, data, inv_diag, b, x, i):  # pragma: no cover - compiled
    """One Gauss-Seidel (SOR) update of row ``i``."""
    acc = b[i]
    for t in range(indptr[i], indptr[i + 1]):
        acc -= data[t] * x[indices[t]]
    x[i] += acc * inv_diag[i]


@numba.njit(cache=True)
def gs_sweeps(indptr, indices, data, inv_diag, b, x, sweeps, forward):  # pragma: no cover
    """``sweeps`` Gauss-Seidel (SOR) sweeps on ``A x = b``, in place: rows in increasing order
    (``forward``) or decreasing order (the adjoint sweep in the ``A`` inner product)."""
    n = b.shape[0]
    for _ in range(sweeps):
        if forward:
            for i in range(n):
                _relax(indptr, indices, data, inv_diag, b, x, i)
        else:
            for i in range(n - 1, -1, -1):
                _relax(indptr, indices, data, inv_diag, b, x, i)


@numba.njit(cache=True)
def gs_forward_zero(indptr, indices, data, inv_diag, b, x, sweeps):  # pragma: no cover - compiled
    """Forward :func:`gs_sweeps` from ``x = 0`` (overwritten): the first sweep reads only the rows
    already visited (``x_j = 0`` for ``j > i``)."""
    n = b.shape[0]
    for i in range(n):
        acc = b[i]
        for t in range(indptr[i], indptr[i + 1]):
            j = indices[t]
            if j < i:
                acc -= data[t] * x[j]
        x[i] = acc * inv_diag[i]
    for _ in range(sweeps - 1):  # the remaining forward sweeps (not a call of gs_sweeps with a
        for i in range(n):       # literal True: numba compiled that as a second specialisation)
            _relax(indptr, indices, data, inv_diag, b, x, i)


@numba.njit(cache=True)
def residual(indptr, indices, data, b, x, r):  # pragma: no cover - compiled
    """``r = b - A x``."""
    n = b.shape[0]
    for i in range(n):
        acc = b[i]
        for t in range(indptr[i], indptr[i + 1]):
            acc -= data[t] * x[indices[t]]
        r[i] = acc


@numba.njit(cache=True)
def add_matvec(indptr, indices, data, u, y):  # pragma: no cover - compiled
    """``y += P u`` for a CSR ``P`` (the prolongation: one or two entries per row)."""
    n = y.shape[0]
    for i in range(n):
        acc = 0.0
        for t in range(indptr[i], indptr[i + 1]):
            acc += data[t] * u[indices[t]]
        y[i] += acc




@numba.njit(cache=True)
def transpose(indptr, indices, data, n_cols):  # pragma: no cover - compiled
    """CSR of ``P^T`` from the CSR ``(indptr, indices, data)`` of an ``(n_rows, n_cols)`` matrix
    ``P``: a counting sort by column (Gustavson's permuted transposition with the identity
    permutation), O(nnz + n_rows + n_cols). Rows of the result have increasing column indices
    (duplicates of ``P`` stay duplicates); ``indptr`` is int64, the indices keep their dtype."""
    n_rows = indptr.shape[0] - 1
    nnz = indptr[n_rows]
    counts = np.zeros(n_cols, np.int64)
    for t in range(nnz):
        counts[indices[t]] += 1
    t_indptr = np.empty(n_cols + 1, np.int64)
    total = 0
    for c in range(n_cols):
        t_indptr[c] = total
        total += counts[c]
    t_indptr[n_cols] = total
    fill = t_indptr[:n_cols].copy()
    t_indices = np.empty(nnz, indices.dtype)
    t_data = np.empty(nnz, data.dtype)
    for i in range(n_rows):
        for t in range(indptr[i], indptr[i + 1]):
            c = indices[t]
            q = fill[c]
            t_indices[q] = i
            t_data[q] = data[t]
            fill[c] = q + 1
    return t_indptr, t_indices, t_data


@numba.njit(cache=True, inline="always")
def _sort_row(cols, m):  # pragma: no cover - compiled
    """Sort ``cols[:m]`` in place: insertion sort for the short rows of a coarse operator
    (about 7 entries for P1 triangles), Shell's sort with Knuth's gaps 1, 4, 13, ... for long
    ones (a general ``P`` may give any row length; Knuth, TAOCP vol. 3, 5.2.1). Not numpy's
    sort: its compilation alone took 15-25 s of a first run's 18 s compile stage."""
    if m > 32:
        gap = 1
        while gap < m // 3:
            gap = 3 * gap + 1
        while gap > 0:
            for q in range(gap, m):
                c = cols[q]
                p = q
                while p >= gap and cols[p - gap] > c:
                    cols[p] = cols[p - gap]
                    p -= gap
                cols[p] = c
            gap //= 3
        return
    for q in range(1, m):
        c = cols[q]
        p = q - 1
        while p >= 0 and cols[p] > c:
            cols[p + 1] = cols[p]
            p -= 1
        cols[p + 1] = c


def galerkin(pt_indptr, pt_indices, pt_data, a_indptr, a_indices, a_data,
             p_indptr, p_indices, p_data, capacity):
    """``C = P^T A P`` and its diagonal, row by row (Gustavson's row-wise product).

    ``P^T`` (the CSR of :func:`transpose`), ``A`` and ``P`` are CSR triples; ``P`` is
    ``(n_fine, n_coarse)``. Row ``i`` of ``C`` is ``sum_k P_ki sum_j a_kj P_j:``, accumulated in a
    dense array of the coarse size, with a marker holding the last row that touched each column
    (so neither array is cleared between rows). The touched columns are then sorted and exact
    zeros dropped, as SciPy's product drops them: ``C`` is canonical CSR (sorted, no duplicates;
    duplicates in the inputs are summed). Work: ``sum_k nnz(P_k:) sum_(j in A_k:) nnz(P_j:)``, one
    pass; the output starts at ``capacity`` entries and grows by doubling here, between calls of
    the compiled pass (:func:`_galerkin_rows`, which stops at a row that does not fit: growing
    arrays inside the compiled loop made its compilation 4x slower, 11 s of a first run), and is
    returned as views of its buffers. Column indices keep ``p_indices``' dtype, ``indptr`` is
    int64.
    """
    nc = pt_indptr.shape[0] - 1
    c_indptr = np.empty(nc + 1, np.int64)
    c_indptr[0] = 0
    c_indices = np.empty(max(capacity, 1), p_indices.dtype)
    c_data = np.empty(max(capacity, 1), np.float64)
    diag = np.zeros(nc)
    acc = np.empty(nc)      # acc[c] is set when row i first touches c (marker[c] != i)
    marker = np.full(nc, -1, np.int64)
    cols = np.empty(nc, np.int64)
    row = pos = 0
    while True:
        row, pos, need = _galerkin_rows(pt_indptr, pt_indices, pt_data, a_indptr, a_indices,
                                        a_data, p_indptr, p_indices, p_data, row, pos, c_indptr,
                                        c_indices, c_data, diag, acc, marker, cols)
        if row == nc:
            return c_indptr, c_indices[:pos], c_data[:pos], diag
        grown = max(2 * c_data.shape[0], pos + need)
        c_indices = np.concatenate([c_indices[:pos], np.empty(grown - pos, c_indices.dtype)])
        c_data = np.concatenate([c_data[:pos], np.empty(grown - pos)])


@numba.njit(cache=True)
def _galerkin_rows(pt_indptr, pt_indices, pt_data, a_indptr, a_indices, a_data,
                   p_indptr, p_indices, p_data, row, pos, c_indptr, c_indices, c_data, diag,
                   acc, marker, cols):  # pragma: no cover - compiled
    """Rows ``row, row + 1, ...`` of :func:`galerkin`, written from entry ``pos`` on, until the
    last row or a row whose entries do not fit in ``c_data``; returns ``(next row, pos, entries
    of that row)`` (the row is left untouched, its markers cleared, so it is redone)."""
    nc = pt_indptr.shape[0] - 1
    for i in range(row, nc):
        m = 0
        for s in range(pt_indptr[i], pt_indptr[i + 1]):
            k = pt_indices[s]
            w = pt_data[s]
            for t in range(a_indptr[k], a_indptr[k + 1]):
                j = a_indices[t]
                wa = w * a_data[t]
                for u in range(p_indptr[j], p_indptr[j + 1]):
                    c = p_indices[u]
                    if marker[c] != i:
                        marker[c] = i
                        cols[m] = c
                        m += 1
                        acc[c] = wa * p_data[u]
                    else:
                        acc[c] += wa * p_data[u]
        if pos + m > c_data.shape[0]:
            for q in range(m):
                marker[cols[q]] = -1
            return i, pos, m
        _sort_row(cols, m)
        for q in range(m):
            c = cols[q]
            v = acc[c]
            if v != 0.0:
                c_indices[pos] = c
                c_data[pos] = v
                pos += 1
                if c == i:
                    diag[i] = v
        c_indptr[i + 1] = pos
    return nc, pos, 0
