"""Compiled (numba) quality numbers of a triangle mesh: one pass over the triangles.

Behind :func:`femkit.mesh.quality` on large meshes (:data:`femkit.mesh.quality.NUMBA_THRESHOLD`
triangles and more); the formulas are those of the NumPy path, so the numbers agree to
round-off. Compiled once and cached on disk (``cache=True``), serial.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, error_model="numpy")  # 0 / 0 is NaN (a degenerate triangle), no raise
def triangle_quality(points, tri):  # pragma: no cover - compiled
    """``(h_max, h_min, min_angle, max_angle, max_aspect, sum_aspect, area_sum)`` over the
    triangles: side lengths, angles by the law of cosines (degrees, NaN for a degenerate
    triangle, ignored like ``np.nanmin``; the extreme angles are the arccos of the extreme
    cosines, the same numbers as the extremes of every angle), aspect ratio ``R / (2 r)`` (inf when the area is 0)."""
    h_max, h_min = -np.inf, np.inf
    c_max, c_min = np.nan, np.nan  # the extreme cosines: the angle is decreasing in its cosine
    asp_max, asp_sum, area_sum = -np.inf, 0.0, 0.0
    blk_asp, blk_area = 0.0, 0.0  # sums per block of 4096 triangles: round-off ~ pairwise
    rad = 180.0 / np.pi
    lens = np.empty(3)
    for e in range(tri.shape[0]):
        i0, i1, i2 = tri[e, 0], tri[e, 1], tri[e, 2]
        x0, y0 = points[i0, 0], points[i0, 1]
        x1, y1 = points[i1, 0], points[i1, 1]
        x2, y2 = points[i2, 0], points[i2, 1]
        lens[0] = np.sqrt((x2 - x1) ** 2 + (y2 - y1) ** 2)   # opposite vertex 0
        lens[1] = np.sqrt((x0 - x2) ** 2 + (y0 - y2) ** 2)
        lens[2] = np.sqrt((x1 - x0) ** 2 + (y1 - y0) ** 2)
        for k in range(3):
            a, b, c = lens[k], lens[(k + 1) % 3], lens[(k + 2) % 3]
            h_max = max(h_max, a)
            h_min = min(h_min, a)
            cosang = (b * b + c * c - a * a) / (2.0 * b * c)
            if cosang == cosang:  # NaN for a degenerate triangle: skipped like nanmin
                if not (c_max >= cosang):
                    c_max = cosang
                if not (c_min <= cosang):
                    c_min = cosang
        area = abs(0.5 * ((x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)))
        blk_area += area
        if area > 0:
            half = 0.5 * (lens[0] + lens[1] + lens[2])
            circum = lens[0] * lens[1] * lens[2] / (4.0 * area)
            aspect = circum / (2.0 * (area / half))
        else:
            aspect = np.inf
        asp_max = max(asp_max, aspect)
        blk_asp += aspect
        if (e & 4095) == 4095:
            asp_sum += blk_asp
            area_sum += blk_area
            blk_asp, blk_area = 0.0, 0.0
    asp_sum += blk_asp
    area_sum += blk_area
    # two arccos instead of three per triangle: the smallest angle is that of the largest cosine
    a_min = np.arccos(min(max(c_max, -1.0), 1.0)) * rad  # NaN stays NaN (no angle at all)
    a_max = np.arccos(min(max(c_min, -1.0), 1.0)) * rad
    return h_max, h_min, a_min, a_max, asp_max, asp_sum, area_sum


@numba.njit(cache=True)
def mean_edge_length(points, edge_nodes):  # pragma: no cover - compiled
    """Mean length of the edges ``edge_nodes`` (E, 2) of a 2D mesh."""
    s, blk = 0.0, 0.0
    for i in range(edge_nodes.shape[0]):
        a, b = edge_nodes[i, 0], edge_nodes[i, 1]
        blk += np.hypot(points[b, 0] - points[a, 0], points[b, 1] - points[a, 1])
        if (i & 4095) == 4095:
            s += blk
            blk = 0.0
    return (s + blk) / max(edge_nodes.shape[0], 1)


def warm_up() -> None:
    """Compile (or load from the on-disk cache) both kernels."""
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    triangle_quality(pts, np.array([[0, 1, 2]], np.int64))
    mean_edge_length(pts, np.array([[0, 1]], np.int64))
