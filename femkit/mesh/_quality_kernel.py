"""Compiled (numba) quality numbers of a triangle mesh: one pass over the triangles.

Behind :func:`femkit.mesh.quality` on large meshes (:data:`femkit.mesh.quality.NUMBA_THRESHOLD`
triangles and more); the formulas are those of the NumPy path, so the numbers agree to
round-off. Compiled once and cached on disk (``cache=True``), serial.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True, error_model="numpy")  # 0 / 0 is NaN (a degenerate triangle), no raise
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


@numba.njit(cache=True, nogil=True)
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




@numba.njit(cache=True, nogil=True, error_model="numpy")  # 0 / 0 is NaN (a flat tetrahedron), no raise
def tetrahedron_quality(points, tets, faces, pairs, ratio, volume):  # pragma: no cover - compiled
    """One pass over the tetrahedra: ``(c_min, c_max)``, the extreme cosines between outward
    face normals (NaN ones skipped, like ``np.nanmin``; the dihedral angle ``180 - acos(c)`` is
    increasing in ``c``), and per tetrahedron its radius ratio ``3 r_in / R_circ`` into
    ``ratio`` and its volume into ``volume``.

    ``faces``: :data:`femkit.mesh.faces.LOCAL_FACES`; ``pairs``: the face pairs of the six
    dihedral angles. Every number is formed by the operations, in the order, of the NumPy
    formulas of :mod:`femkit.mesh.quality` (``np.cross``; ``np.linalg.norm`` sums in order,
    ``einsum`` over three terms as ``(x0 y0 + x2 y2) + x1 y1``), so the per-element values are
    the same floats (the tests compare them bit for bit with NumPy's).
    """
    c_min, c_max = np.nan, np.nan
    normal = np.empty((4, 3))
    cr = np.empty(3)
    for e in range(tets.shape[0]):
        area = 0.0
        for f in range(4):
            a, b, c = tets[e, faces[f, 0]], tets[e, faces[f, 1]], tets[e, faces[f, 2]]
            u0, u1, u2 = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1], points[b, 2] - points[a, 2]
            w0, w1, w2 = points[c, 0] - points[a, 0], points[c, 1] - points[a, 1], points[c, 2] - points[a, 2]
            cr[0], cr[1], cr[2] = u1 * w2 - u2 * w1, u2 * w0 - u0 * w2, u0 * w1 - u1 * w0
            nrm = np.sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2])
            for k in range(3):
                normal[f, k] = cr[k] / nrm
            area += 0.5 * nrm
        for j in range(pairs.shape[0]):
            f, g = pairs[j, 0], pairs[j, 1]
            cos = (normal[f, 0] * normal[g, 0] + normal[f, 2] * normal[g, 2]) + normal[f, 1] * normal[g, 1]
            cos = min(max(cos, -1.0), 1.0)
            if cos == cos:
                if not (c_max >= cos):
                    c_max = cos
                if not (c_min <= cos):
                    c_min = cos
        i0, i1, i2, i3 = tets[e, 0], tets[e, 1], tets[e, 2], tets[e, 3]
        a0, a1, a2 = points[i1, 0] - points[i0, 0], points[i1, 1] - points[i0, 1], points[i1, 2] - points[i0, 2]
        b0, b1, b2 = points[i2, 0] - points[i0, 0], points[i2, 1] - points[i0, 1], points[i2, 2] - points[i0, 2]
        c0, c1, c2 = points[i3, 0] - points[i0, 0], points[i3, 1] - points[i0, 1], points[i3, 2] - points[i0, 2]
        bc0, bc1, bc2 = b1 * c2 - b2 * c1, b2 * c0 - b0 * c2, b0 * c1 - b1 * c0
        ca0, ca1, ca2 = c1 * a2 - c2 * a1, c2 * a0 - c0 * a2, c0 * a1 - c1 * a0
        ab0, ab1, ab2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
        det = (a0 * bc0 + a2 * bc2) + a1 * bc1  # einsum's order over three terms
        vol6 = abs(det)
        volume[e] = abs(det / 6.0)
        sa = (a0 * a0 + a2 * a2) + a1 * a1
        sb = (b0 * b0 + b2 * b2) + b1 * b1
        sc = (c0 * c0 + c2 * c2) + c1 * c1
        n0 = sa * bc0 + sb * ca0 + sc * ab0
        n1 = sa * bc1 + sb * ca1 + sc * ab1
        n2 = sa * bc2 + sb * ca2 + sc * ab2
        num = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        if vol6 > 0:
            r_in = 0.5 * vol6 / area
            r_circ = num / (2.0 * vol6)
            ratio[e] = 3.0 * r_in / r_circ
        else:
            ratio[e] = 0.0
    return c_min, c_max


@numba.njit(cache=True, nogil=True)
def edge_lengths(points, edge_nodes):  # pragma: no cover - compiled
    """Length of every edge ``edge_nodes`` (E, 2) of a 3D mesh (as ``np.linalg.norm`` forms it)."""
    out = np.empty(edge_nodes.shape[0])
    for i in range(edge_nodes.shape[0]):
        a, b = edge_nodes[i, 0], edge_nodes[i, 1]
        d0, d1, d2 = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1], points[b, 2] - points[a, 2]
        out[i] = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    return out


def warm_up() -> None:
    """Compile (or load from the on-disk cache) the kernels."""
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    triangle_quality(pts, np.array([[0, 1, 2]], np.int64))
    mean_edge_length(pts, np.array([[0, 1]], np.int32))
    tet = np.array([[0, 1, 2, 3]], np.int64)
    pts3 = np.eye(4, 3)[[3, 0, 1, 2]]
    tetrahedron_quality(pts3, tet, np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]]),
                        np.array([[0, 1]]), np.empty(1), np.empty(1))
    edge_lengths(pts3, np.array([[0, 1]], np.int32))
