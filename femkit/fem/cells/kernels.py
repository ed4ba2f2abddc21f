"""Compiled geometry of one cell, shared by every compiled pass of :mod:`femkit.fem`.

A triangle's vertices, edge vectors and area (:func:`_triangle`), a tetrahedron's scaled shape
gradients and ``6 V_signed`` (:func:`_tetrahedron`, :func:`_volume6`): the assembly kernels
(:mod:`femkit.fem._kernels`), the fused quadrature passes (:mod:`femkit.fem.fused.templates`) and
the estimator's face pass (:mod:`femkit.fem.estimators._kernels3d`) all call these, so they sit
below all three.
"""

from __future__ import annotations

import numba


@numba.njit(cache=True)
def _triangle(tri, points, e):  # pragma: no cover - compiled
    """Vertices, edges opposite each vertex ``(ex_a, ey_a)`` and area of element ``e``."""
    i0, i1, i2 = tri[e, 0], tri[e, 1], tri[e, 2]
    ex0, ey0 = points[i2, 0] - points[i1, 0], points[i2, 1] - points[i1, 1]
    ex1, ey1 = points[i0, 0] - points[i2, 0], points[i0, 1] - points[i2, 1]
    ex2, ey2 = points[i1, 0] - points[i0, 0], points[i1, 1] - points[i0, 1]
    area = 0.5 * abs(ex2 * ey0 - ey2 * ex0)
    return i0, i1, i2, ex0, ey0, ex1, ey1, ex2, ey2, area


@numba.njit(cache=True)
def _tetrahedron(tets, points, e, g):  # pragma: no cover - compiled
    """Fill ``g`` (4, 3) with ``D grad N_a`` of element ``e`` (rows ``b x c, c x a, a x b`` for
    vertices 1..3, minus their sum for vertex 0; a buffer reused over the elements, no
    allocation per element) and return ``D = 6 V_signed``."""
    i0, i1, i2, i3 = tets[e, 0], tets[e, 1], tets[e, 2], tets[e, 3]
    ax, ay, az = points[i1, 0] - points[i0, 0], points[i1, 1] - points[i0, 1], points[i1, 2] - points[i0, 2]
    bx, by, bz = points[i2, 0] - points[i0, 0], points[i2, 1] - points[i0, 1], points[i2, 2] - points[i0, 2]
    cx, cy, cz = points[i3, 0] - points[i0, 0], points[i3, 1] - points[i0, 1], points[i3, 2] - points[i0, 2]
    g[1, 0], g[1, 1], g[1, 2] = by * cz - bz * cy, bz * cx - bx * cz, bx * cy - by * cx
    g[2, 0], g[2, 1], g[2, 2] = cy * az - cz * ay, cz * ax - cx * az, cx * ay - cy * ax
    g[3, 0], g[3, 1], g[3, 2] = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    for d in range(3):
        g[0, d] = -(g[1, d] + g[2, d] + g[3, d])
    return ax * g[1, 0] + ay * g[1, 1] + az * g[1, 2]


@numba.njit(cache=True)
def _volume6(tets, points, e):  # pragma: no cover - compiled
    """``D = 6 V_signed`` of element ``e``."""
    i0, i1, i2, i3 = tets[e, 0], tets[e, 1], tets[e, 2], tets[e, 3]
    ax, ay, az = points[i1, 0] - points[i0, 0], points[i1, 1] - points[i0, 1], points[i1, 2] - points[i0, 2]
    bx, by, bz = points[i2, 0] - points[i0, 0], points[i2, 1] - points[i0, 1], points[i2, 2] - points[i0, 2]
    cx, cy, cz = points[i3, 0] - points[i0, 0], points[i3, 1] - points[i0, 1], points[i3, 2] - points[i0, 2]
    return ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx)
