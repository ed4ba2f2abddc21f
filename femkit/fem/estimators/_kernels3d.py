"""Compiled (numba) pass of the residual estimator on tetrahedra; imported only for a large mesh.

It computes what :func:`~femkit.fem.estimators.geometry.element_fields` and
:func:`~femkit.fem.estimators.residual_faces.residual_terms_3d` compute with NumPy, with the same
formulas, element by element (sums over the elements in the order of ``np.bincount``), so the
numbers agree to round-off; no (m, 4, 3) array of basis gradients is formed.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..cells.kernels import _tetrahedron


@numba.njit(cache=True, inline="always")
def _longest_sq(points, i, j, sq):  # pragma: no cover - compiled
    s = 0.0
    for d in range(3):
        t = points[i, d] - points[j, d]
        s += t * t
    return max(sq, s)


@numba.njit(cache=True, error_model="numpy")
def residual_faces(points, tets, u, kappa, tf, face_nodes, count, c_half):  # pragma: no cover - compiled
    """Per tetrahedron: ``volume``, longest edge ``h_T``, ``q_area`` (m, 4) (outward flux times
    face area), ``face_area`` (m, 4) and the interior faces' ``jump`` term (times ``c_half`` =
    ``c_J^2 / 2``); per face its longest edge ``h_F``. Returns these and the number of
    tetrahedra of zero or non-finite volume (then nothing else is meaningful)."""
    m = tets.shape[0]
    n_faces = face_nodes.shape[0]
    vol = np.empty(m)
    h_t = np.empty(m)
    q_area = np.empty((m, 4))
    face_area = np.empty((m, 4))
    jump_area = np.zeros(n_faces)
    kmax = np.zeros(n_faces)
    area_f = np.zeros(n_faces)
    g = np.empty((4, 3))
    gn = np.empty(3)
    bad = 0
    for e in range(m):
        det = _tetrahedron(tets, points, e, g)      # g_k = det grad N_k
        v = abs(det) / 6.0
        if not (v > 0.0 and v < np.inf):
            bad += 1
            continue
        vol[e] = v
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        for k in range(4):
            uk = u[tets[e, k]]
            s0 += uk * (g[k, 0] / det)
            s1 += uk * (g[k, 1] / det)
            s2 += uk * (g[k, 2] / det)
        kap = kappa[e]
        for k in range(4):
            for d in range(3):
                gn[d] = g[k, d] / det
            q = -3.0 * v * (kap * s0 * gn[0] + kap * s1 * gn[1] + kap * s2 * gn[2])
            fa = 3.0 * v * math.sqrt(gn[0] * gn[0] + gn[1] * gn[1] + gn[2] * gn[2])
            q_area[e, k] = q
            face_area[e, k] = fa
            f = tf[e, k]
            jump_area[f] += q
            if kap > kmax[f]:
                kmax[f] = kap
            area_f[f] = fa
        sq = 0.0
        for a in range(4):
            for b in range(a + 1, 4):
                sq = _longest_sq(points, tets[e, a], tets[e, b], sq)
        h_t[e] = math.sqrt(sq)
    h_f = np.empty(n_faces)
    eta = np.zeros(n_faces)
    for f in range(n_faces):
        i, j, k = face_nodes[f, 0], face_nodes[f, 1], face_nodes[f, 2]
        sq = _longest_sq(points, i, j, 0.0)
        sq = _longest_sq(points, i, k, sq)
        sq = _longest_sq(points, j, k, sq)
        h_f[f] = math.sqrt(sq)
        if count[f] == 2:
            eta[f] = h_f[f] * jump_area[f] ** 2 / (area_f[f] * kmax[f])
    jump = np.empty(m)
    for e in range(m):
        jump[e] = c_half * (eta[tf[e, 0]] + eta[tf[e, 1]] + eta[tf[e, 2]] + eta[tf[e, 3]])
    return vol, h_t, q_area, face_area, jump, h_f, bad
