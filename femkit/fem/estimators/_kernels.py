"""Compiled (numba) passes of the residual estimator on triangles; imported only for a large mesh.

Each computes what :mod:`.geometry` and :mod:`.residual` compute with NumPy, with the same
formulas in the same order (element by element, sums in the order of ``np.bincount``), so the
numbers are the same to the last bit. :func:`residual_pass` reads the mesh, the solution and the
element -> edge map and writes only its outputs (the volume and jump terms per element): no
(m, 3, 2) edge vectors, no (m, 3) lengths or fluxes; its only scratch is one float and one byte
per edge (the summed flux and how many triangles share the edge), plus one float per edge for
the larger neighbour's kappa when kappa varies.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, inline="always", error_model="numpy")
def _triangle(points, tri, u, k, e, grad):  # pragma: no cover - compiled
    """Edge vectors ``e`` (3, 2) and ``grad u_h`` (2,) of triangle ``k`` as
    :func:`~femkit.fem._elements.triangle_geometry` and :func:`~femkit.fem._elements.p1_gradients`
    form them; returns the signed area."""
    i0, i1, i2 = tri[k, 0], tri[k, 1], tri[k, 2]
    for d in range(2):
        e[0, d] = points[i2, d] - points[i1, d]
        e[1, d] = points[i0, d] - points[i2, d]
        e[2, d] = points[i1, d] - points[i0, d]
    signed = 0.5 * (e[2, 0] * (-e[1, 1]) - e[2, 1] * (-e[1, 0]))
    inv = 1.0 / (2.0 * signed)
    grad[0] = -(u[i0] * e[0, 1] + u[i1] * e[1, 1] + u[i2] * e[2, 1]) * inv
    grad[1] = (u[i0] * e[0, 0] + u[i1] * e[1, 0] + u[i2] * e[2, 0]) * inv
    return signed


#: Squared lengths below ``(1 - _TIE) x`` the largest are of edges shorter than the longest by
#: more than hypot's rounding (< 1 ulp) and the squares' (< 2 ulp) can hide.
_TIE = 1e-14


@numba.njit(cache=True, inline="always", error_model="numpy")
def _longest(e):  # pragma: no cover - compiled
    """``max_j hypot(e[j])`` of the three edge vectors ``e`` (3, 2) (``h_T``), with ``hypot`` only
    for the edges whose squared length is within :data:`_TIE` of the largest: the same value
    (the others' ``hypot`` is smaller), usually one call instead of three. All three when a
    square overflowed or may have lost digits to underflow, or is not a number (then the
    first edge's, as the loop over the edges that took the first and any longer one)."""
    s0 = e[0, 0] * e[0, 0] + e[0, 1] * e[0, 1]
    s1 = e[1, 0] * e[1, 0] + e[1, 1] * e[1, 1]
    s2 = e[2, 0] * e[2, 0] + e[2, 1] * e[2, 1]
    big = max(s0, max(s1, s2))
    if not (big > 1e-280 and big < np.inf):
        h = math.hypot(e[0, 0], e[0, 1])
        for j in range(1, 3):
            length = math.hypot(e[j, 0], e[j, 1])
            if length > h:
                h = length
        return h
    cut = big * (1.0 - _TIE)
    h = math.hypot(e[0, 0], e[0, 1]) if s0 >= cut else 0.0
    if s1 >= cut:
        h = max(h, math.hypot(e[1, 0], e[1, 1]))
    if s2 >= cut:
        h = max(h, math.hypot(e[2, 0], e[2, 1]))
    return h


@numba.njit(cache=True, nogil=True, error_model="numpy")
def triangle_fields(points, tri, u, e, area, grad):  # pragma: no cover - compiled
    """Fill ``e`` (m, 3, 2), ``area`` and ``grad`` (m, 2) as
    :func:`~femkit.fem._elements.triangle_geometry` and :func:`~femkit.fem._elements.p1_gradients`
    do; returns the number of triangles of zero or non-finite area."""
    bad = 0
    for k in range(tri.shape[0]):
        area[k] = abs(_triangle(points, tri, u, k, e[k], grad[k]))
        if not (area[k] > 0.0 and area[k] < np.inf):
            bad += 1
    return bad


@numba.njit(cache=True, nogil=True, error_model="numpy")
def residual_pass(points, tri, u, kappa, te, n_edges, fsq, f_sq, c_volume_sq, jump_factor,
                  volume, jump, count):  # pragma: no cover - compiled
    """The volume and jump terms of every triangle; returns the number of degenerate triangles.

    ``kappa`` (m,) per element, or (1,) when it is the same everywhere; ``te`` (m, 3) the
    element -> edge map of ``n_edges`` edges; ``fsq`` (m,) ``||f||_T^2`` per element, or empty for
    a constant source whose square is ``f_sq`` (then ``||f||_T^2 = |T| f_sq``). Writes
    ``volume[k] = c_V^2 h_T^2 ||f||_T^2 / kappa_T`` (``volume`` may be ``fsq`` itself: each entry
    is read before it is written), ``jump[k] = jump_factor * sum_E jump_E^2 / kappa_E`` over the
    interior edges of ``k`` and ``count[E]``, the triangles sharing each edge (saturating at 255).
    """
    m = tri.shape[0]
    uniform = kappa.shape[0] == 1
    constant_f = fsq.shape[0] == 0
    jump_len = np.zeros(n_edges)                       # the flux jump times the edge length
    kmax = np.zeros(1 if uniform else n_edges)
    e = np.empty((3, 2))
    grad = np.empty(2)
    bad = 0
    for k in range(m):
        signed = _triangle(points, tri, u, k, e, grad)
        area = abs(signed)
        if not (area > 0.0 and area < np.inf):
            bad += 1
        kk = kappa[0] if uniform else kappa[k]
        s0 = kk * grad[0]
        s1 = kk * grad[1]
        h = _longest(e)
        for j in range(3):
            i = te[k, j]
            jump_len[i] += s0 * e[j, 1] - s1 * e[j, 0]       # outward flux times the length
            if count[i] < 255:
                count[i] += 1
            if not uniform and kk > kmax[i]:
                kmax[i] = kk
        fs = area * f_sq if constant_f else fsq[k]
        volume[k] = c_volume_sq * (h * h) * fs / kk
    for k in range(m):
        acc = 0.0
        for j in range(3):
            i = te[k, j]
            km = kappa[0] if uniform else kmax[i]
            acc += jump_len[i] ** 2 / km if count[i] == 2 else 0.0
        jump[k] = jump_factor * acc
    return bad


@numba.njit(cache=True, nogil=True, error_model="numpy")
def slot_fluxes(points, tri, u, kappa, elem, local):  # pragma: no cover - compiled
    """``(length, flux * length)`` of the local edge ``local[i]`` of triangle ``elem[i]``: the
    numbers :func:`residual_pass` forms for that edge (the boundary edges' Neumann term)."""
    n = elem.shape[0]
    lens = np.empty(n)
    qlen = np.empty(n)
    e = np.empty((3, 2))
    grad = np.empty(2)
    uniform = kappa.shape[0] == 1
    for s in range(n):
        k, j = elem[s], local[s]
        _triangle(points, tri, u, k, e, grad)
        kk = kappa[0] if uniform else kappa[k]
        lens[s] = math.hypot(e[j, 0], e[j, 1])
        qlen[s] = (kk * grad[0]) * e[j, 1] - (kk * grad[1]) * e[j, 0]
    return lens, qlen


@numba.njit(cache=True, nogil=True, error_model="numpy")
def squares_by_tag(tags, uniq, ind):  # pragma: no cover - compiled
    """``sum ind^2`` per value of ``uniq`` (sorted, every tag among them), element by element:
    ``np.bincount(inverse, weights=ind ** 2)`` without the inverse map and the squares (each tag
    found by bisection: no call into numba's array library, whose import a cached load would pay)."""
    out = np.zeros(uniq.shape[0])
    for k in range(tags.shape[0]):
        t = tags[k]
        lo, hi = 0, uniq.shape[0] - 1                  # bisection: the first uniq[i] >= t
        while lo < hi:
            mid = (lo + hi) // 2
            if uniq[mid] < t:
                lo = mid + 1
            else:
                hi = mid
        out[lo] += ind[k] * ind[k]
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def triangle_areas(points, tri):  # pragma: no cover - compiled
    """``|T|`` of every triangle, as :func:`triangle_fields` computes it."""
    area = np.empty(tri.shape[0])
    e = np.empty((3, 2))
    for k in range(tri.shape[0]):
        i0, i1, i2 = tri[k, 0], tri[k, 1], tri[k, 2]
        for d in range(2):
            e[1, d] = points[i0, d] - points[i2, d]
            e[2, d] = points[i1, d] - points[i0, d]
        area[k] = abs(0.5 * (e[2, 0] * (-e[1, 1]) - e[2, 1] * (-e[1, 0])))
    return area


def warm_up() -> None:
    """Compile (or load from the on-disk cache) every pass with the argument types of a run:
    int64 cells, int32 edges and tags (the Neumann and area passes are not met by the warm-up's
    all-Dirichlet case with a kept source norm)."""
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    tri = np.array([[0, 1, 2]], np.int64)
    te = np.array([[0, 1, 2]], np.int32)
    u, one = np.zeros(3), np.ones(1)
    residual_pass(points, tri, u, one, te, 3, np.ones(1), 0.0, 1.0, 1.0, np.empty(1), np.empty(1),
                  np.zeros(3, np.uint8))
    slot_fluxes(points, tri, u, one, np.zeros(1, np.int64), np.zeros(1, np.int64))
    triangle_areas(points, tri)
    squares_by_tag(np.zeros(1, np.int32), np.zeros(1, np.int32), one)
