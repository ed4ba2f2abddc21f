"""numba kernels of the geometric multigrid V-cycle (imported lazily by :mod:`.gmg`; imports numba).

Matrices are CSR ``(indptr, indices, data)`` of a symmetric matrix with a positive diagonal.
Gauss-Seidel / SOR is written as ``x_i += omega (b_i - sum_j a_ij x_j) / a_ii`` with
``inv_diag = omega / diag(A)`` (the row sum includes the diagonal), so no diagonal-free copy of
``A`` is needed.
"""

from __future__ import annotations

import numba


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
    gs_sweeps(indptr, indices, data, inv_diag, b, x, sweeps - 1, True)


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


