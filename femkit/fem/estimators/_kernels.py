"""Compiled (numba) passes of the residual estimator on triangles; imported only for a large mesh.

Each computes what :mod:`.geometry` and :mod:`.residual` compute with NumPy, with the same
formulas in the same order (element by element, sums in the order of ``np.bincount``), so the
numbers are the same to the last bit; one pass over the elements instead of some forty array
operations over (m, 3) arrays.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def triangle_fields(points, tri, u, e, area, grad):  # pragma: no cover - compiled
    """Fill ``e`` (m, 3, 2), ``area`` and ``grad`` (m, 2) as
    :func:`~femkit.fem._elements.triangle_geometry` and :func:`~femkit.fem._elements.p1_gradients`
    do; returns the number of triangles of zero or non-finite area."""
    bad = 0
    for k in range(tri.shape[0]):
        i0, i1, i2 = tri[k, 0], tri[k, 1], tri[k, 2]
        for d in range(2):
            e[k, 0, d] = points[i2, d] - points[i1, d]
            e[k, 1, d] = points[i0, d] - points[i2, d]
            e[k, 2, d] = points[i1, d] - points[i0, d]
        signed = 0.5 * (e[k, 2, 0] * (-e[k, 1, 1]) - e[k, 2, 1] * (-e[k, 1, 0]))
        area[k] = abs(signed)
        if not (area[k] > 0.0 and area[k] < np.inf):
            bad += 1
        inv = 1.0 / (2.0 * signed)
        grad[k, 0] = -(u[i0] * e[k, 0, 1] + u[i1] * e[k, 1, 1] + u[i2] * e[k, 2, 1]) * inv
        grad[k, 1] = (u[i0] * e[k, 0, 0] + u[i1] * e[k, 1, 0] + u[i2] * e[k, 2, 0]) * inv
    return bad


@numba.njit(cache=True)
def residual_edges(e, grad, kappa, te, count, n_edges, jump_factor):  # pragma: no cover - compiled
    """``(lens, qlen, jump)``: edge lengths (m, 3), outward normal flux times length (m, 3) and
    ``jump_factor * sum_k eta_E`` of the interior edges of each element, as
    :func:`~femkit.fem.estimators.residual.residual_estimator` forms them."""
    m = e.shape[0]
    lens = np.empty((m, 3))
    qlen = np.empty((m, 3))
    jump_len = np.zeros(n_edges)
    kmax = np.zeros(n_edges)
    for k in range(m):
        s0 = kappa[k] * grad[k, 0]
        s1 = kappa[k] * grad[k, 1]
        for j in range(3):
            lens[k, j] = math.hypot(e[k, j, 0], e[k, j, 1])
            q = s0 * e[k, j, 1] - s1 * e[k, j, 0]
            qlen[k, j] = q
            i = te[k, j]
            jump_len[i] += q
            if kappa[k] > kmax[i]:
                kmax[i] = kappa[k]
    jump = np.empty(m)
    for k in range(m):
        acc = 0.0
        for j in range(3):
            i = te[k, j]
            acc += jump_len[i] ** 2 / kmax[i] if count[i] == 2 else 0.0
        jump[k] = jump_factor * acc
    return lens, qlen, jump
