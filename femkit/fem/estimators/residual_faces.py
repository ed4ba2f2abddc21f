r"""The residual estimator on tetrahedra: element residual + face jumps (Verfürth 1996, 2013).

The 3D form of :mod:`.residual`, with faces for edges:

.. math::
    \eta_T^2 = c_V^2 \frac{h_T^2}{\kappa_T} \|f\|_T^2
      + c_J^2 \sum_{F \subset \partial T \text{ interior}} \frac{h_F}{2\,\kappa_F} \|[\kappa \partial_n u_h]\|_F^2
      + c_J^2 \sum_{F \subset \partial T \text{ Neumann}} \frac{h_F}{\kappa_T} \|h - \kappa \partial_n u_h\|_F^2

with ``h_T`` the longest edge of ``T``, ``h_F`` the longest edge of the face ``F`` and the same
constants as in 2D. The outward flux through local face ``k`` (opposite vertex ``k``) times its
area is ``-(d |T|) kappa grad u_h . grad N_k`` (``d = 3``): ``grad N_k = -n_k |F_k| / (3 |T|)``,
so no face normal is formed explicitly.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ..coefficients import evaluate_callable
from ..fused import source_norm_sq
from ..quadrature import get_rule, rule_for_degree


def _source_norm_sq(mesh, f, volume: np.ndarray) -> np.ndarray:
    """``||f||_T^2`` per tetrahedron (degree-5 rule for a callable ``f``)."""
    if callable(f):
        rule = rule_for_degree(5, 3)
        fused = source_norm_sq(mesh, f, volume, rule)  # compiled (or kept from the error pass)
        if fused is not None:
            return fused
        fv = evaluate_callable(f, *rule.physical_points(mesh, mesh.cells), name="f")
        return volume * ((fv * fv) @ rule.weights)
    return volume * float(f) ** 2


def _longest(points: np.ndarray, simplices: np.ndarray) -> np.ndarray:
    """Longest edge of each simplex (k, w)."""
    from itertools import combinations

    p = points[simplices]
    return np.sqrt(np.max([np.einsum("kd,kd->k", p[:, a] - p[:, b], p[:, a] - p[:, b])
                           for a, b in combinations(range(simplices.shape[1]), 2)], axis=0))


def _jump_terms(mesh, fl, c_jump: float) -> tuple:
    """``(volume, h_T, q_area, face_area, jump, h_F)`` by NumPy from the element fields."""
    grads, vol, tf, count = fl.e, fl.area, fl.tri_edges, fl.edge_count
    sigma = fl.kappa[:, None] * fl.grad
    q_area = -3.0 * vol[:, None] * np.einsum("md,mkd->mk", sigma, grads)     # flux x |F_k|, (m, 4)
    face_area = 3.0 * vol[:, None] * np.linalg.norm(grads, axis=2)            # |F_k|, (m, 4)
    n_faces = len(fl.edge_nodes)
    jump_area = np.bincount(tf.ravel(), weights=q_area.ravel(), minlength=n_faces)
    kmax = np.zeros(n_faces)
    np.maximum.at(kmax, tf.ravel(), np.repeat(fl.kappa, 4))
    area_f = np.zeros(n_faces)
    area_f[tf.ravel()] = face_area.ravel()
    h_f = _longest(mesh.points, fl.edge_nodes)
    # h_F ||J||_F^2 / kappa_F with ||J||_F^2 = J^2 |F| and J = jump_area / |F|
    interior = count == 2
    eta_face = np.where(interior, h_f * jump_area ** 2 / (np.where(interior, area_f, 1.0) * kmax), 0.0)
    jump = 0.5 * c_jump ** 2 * eta_face[tf].sum(axis=1)
    return vol, _longest(mesh.points, mesh.cells), q_area, face_area, jump, h_f


#: Tetrahedra from which the jump terms are one compiled pass (:mod:`._kernels3d`; below: NumPy).
NUMBA_THRESHOLD = 100_000


def residual_terms_3d(mesh, u: np.ndarray, kappa, f, neumann: Sequence, dirichlet_nodes,
                      c_volume: float, c_jump: float) -> dict:
    """``volume``, ``jump`` and ``neumann`` parts (each (m,), squared) of the P1 solution ``u``
    on a tetrahedral mesh (arguments as :func:`~.residual.residual_estimator`'s)."""
    from ...mesh.faces import LOCAL_FACES, face_ids, faces
    from ..neumann import tagged_facets
    from .geometry import checked_solution, element_fields

    m = mesh.n_cells
    arrays = None
    if m >= NUMBA_THRESHOLD:
        from ..coefficients import element_coefficient
        from ._kernels3d import residual_faces

        u = checked_solution(mesh, u)
        kap = element_coefficient(mesh, kappa)
        face_nodes, tf = faces(mesh)
        count = np.bincount(tf.ravel(), minlength=len(face_nodes))
        *arrays, bad = residual_faces(np.ascontiguousarray(mesh.points, dtype=np.float64),
                                      np.ascontiguousarray(mesh.cells), u, kap, tf, face_nodes,
                                      count, 0.5 * c_jump ** 2)
        arrays = None if bad else arrays           # degenerate: the NumPy path names them
    if arrays is None:
        fl = element_fields(mesh, u, kappa)
        kap, face_nodes, tf, count = fl.kappa, fl.edge_nodes, fl.tri_edges, fl.edge_count
        arrays = _jump_terms(mesh, fl, c_jump)
    vol, h_t, q_area, face_area, jump, h_f = arrays
    volume = c_volume ** 2 * h_t ** 2 * _source_norm_sq(mesh, f, vol) / kap
    bnd = np.flatnonzero(count == 1)
    is_dir = np.zeros(mesh.n_points, dtype=bool)
    if dirichlet_nodes is not None:
        is_dir[np.asarray(dirichlet_nodes, dtype=np.int64)] = True
    bnd = bnd[~is_dir[face_nodes[bnd]].all(axis=1)]
    neumann_part = np.zeros(m)
    if len(bnd):
        rule = get_rule("gauss3")                       # degree 2 on the face
        n_faces = len(face_nodes)
        owner = np.full(n_faces, -1, dtype=np.int64)
        owner[tf.ravel()] = np.arange(tf.size)          # boundary faces have a single owner slot
        slot = owner[bnd]
        elem, k = slot // 4, slot % 4
        corners = mesh.points[mesh.cells[elem[:, None], LOCAL_FACES[k]]]   # (b, 3, 3)
        hq = np.zeros((len(bnd), len(rule.weights)))
        pos = np.full(n_faces, -1, dtype=np.int64)
        pos[bnd] = np.arange(len(bnd))
        for tags, h in neumann:                         # a few entries, not a loop over faces
            ids = pos[face_ids(face_nodes, tagged_facets(mesh, tags))]
            ids = ids[ids >= 0]
            if not len(ids):
                continue
            if callable(h):
                xyz = np.einsum("qa,bad->dbq", rule.points, corners[ids])
                hq[ids] = evaluate_callable(h, *xyz, name="h")
            else:
                hq[ids] = float(h)
        A = face_area[elem, k]
        r = hq - (q_area[elem, k] / A)[:, None]          # h - kappa du_h/dn at the points
        norm_sq = A * ((r * r) @ rule.weights)
        neumann_part = np.bincount(elem, weights=c_jump ** 2 * h_f[bnd] * norm_sq / kap[elem],
                                   minlength=m)
    return {"volume": volume, "jump": jump, "neumann": neumann_part}
