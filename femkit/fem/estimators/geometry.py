"""Per-element quantities both estimators need: gradients, fluxes, edges (faces in 3D) and their
roles."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .._elements import p1_gradients, simplex_gradients, triangle_geometry
from ..coefficients import element_coefficient
from ..sparsity import NUMBA_THRESHOLD
from ...warmup_registry import register_kernels, register_threshold

register_threshold(__name__, "NUMBA_THRESHOLD")
register_kernels("error estimate", "femkit.fem.estimators._kernels", "triangle_areas", rank=4)


@dataclass(frozen=True)
class ElementFields:
    """Geometry and the discrete solution's element-wise data.

    ``e`` (m, 3, 2) edge vectors (``e[:, k]`` opposite local vertex k, from vertex k+1 to k+2),
    ``area`` (m,), ``grad`` (m, 2) = grad u_h, ``kappa`` (m,) barycentre values,
    ``edge_nodes`` (E, 2) and ``tri_edges`` (m, 3) from :func:`femkit.mesh.edges`,
    ``edge_count`` (E,) how many triangles share each edge (1 = boundary, 2 = interior).

    On tetrahedra the facets are faces: ``e`` holds the barycentric gradients (m, 4, 3),
    ``area`` the volumes, ``grad`` (m, 3), ``edge_nodes`` (F, 3) / ``tri_edges`` (m, 4) the
    faces of :func:`femkit.mesh.faces.faces` (local face k opposite vertex k).
    """

    e: np.ndarray
    area: np.ndarray
    grad: np.ndarray
    kappa: np.ndarray
    edge_nodes: np.ndarray
    tri_edges: np.ndarray
    edge_count: np.ndarray


def checked_solution(mesh, u) -> np.ndarray:
    """``u`` as a contiguous float64 array of one finite value per node (else InputError)."""
    from ...errors import InputError

    u = np.ascontiguousarray(u, dtype=np.float64)
    if u.shape != (mesh.n_points,):
        raise InputError(f"u must have one value per node, shape ({mesh.n_points},), got {u.shape}")
    if not np.isfinite(u).all():
        raise InputError("u has non-finite values: no error estimate for it")
    return u


def element_kappa(mesh, kappa) -> np.ndarray:
    """The element values of ``kappa`` (checked as :func:`element_coefficient` does), or one
    value, shape (1,), when it is the same on every element: a constant costs no (m,) array."""
    from ...errors import InputError

    if np.ndim(kappa) == 0 and not callable(kappa) and not isinstance(kappa, (str, Mapping)) \
            and mesh.n_cells:
        try:
            return element_coefficient(mesh, kappa, np.zeros(1, dtype=np.int64))
        except InputError:  # a bad constant: the message of the whole mesh's check
            return element_coefficient(mesh, kappa)
    kap = element_coefficient(mesh, kappa)
    return kap[:1] if len(kap) and kap.min() == kap.max() else kap


def element_fields(mesh, u: np.ndarray, kappa) -> ElementFields:
    """Gradients, kappa and the edge structure of ``mesh`` for the P1 function ``u``."""
    from ...mesh.edges import edges

    u = checked_solution(mesh, u)
    kap = element_coefficient(mesh, kappa)
    if mesh.dim == 3:
        from ...mesh.faces import faces

        grads, volume, tets = simplex_gradients(mesh, None)
        face_nodes, tf = faces(mesh)
        count = np.bincount(tf.ravel(), minlength=len(face_nodes))
        grad = np.einsum("ma,mad->md", u[tets], grads)
        return ElementFields(grads, volume, grad, kap, face_nodes, tf, count)
    if mesh.n_cells >= NUMBA_THRESHOLD:  # one compiled pass, the same numbers
        from ._kernels import triangle_fields

        m = mesh.n_cells
        e, area, grad = np.empty((m, 3, 2)), np.empty(m), np.empty((m, 2))
        if triangle_fields(np.ascontiguousarray(mesh.points, dtype=np.float64),
                           np.ascontiguousarray(mesh.triangles), u, e, area, grad):
            triangle_geometry(mesh, None)  # names the degenerate triangles
    else:
        e, area, signed, tri = triangle_geometry(mesh, None)
        grad = p1_gradients(e, signed, u[tri])
    edge_nodes, te = edges(mesh)
    count = np.bincount(te.ravel(), minlength=len(edge_nodes))
    return ElementFields(e, area, grad, kap, edge_nodes, te, count)
