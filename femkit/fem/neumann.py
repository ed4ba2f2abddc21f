"""Neumann flux ``kappa du/dn = h`` on tagged boundary facets: ``F_i += int_facet h N_i ds``.

Two-point Gauss rule per edge (exact for ``h`` linear along the edge times P1); on the
triangular faces of a tetrahedral mesh the three-point rule ``gauss3`` (degree 2, exact for
``h`` linear on the face times P1).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [2., 0.], [0., 1.]]), np.array([[0, 1, 2]]),
...          boundary_edges=[[0, 1]], boundary_tags=[3])
>>> assemble_neumann(m, 3, 1.5).tolist()
[1.5, 1.5, 0.0]
"""

from __future__ import annotations

from typing import Callable, Iterable, Union

import numpy as np

from ..errors import InputError, MeshError
from .coefficients import evaluate_callable

_S = np.array([0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0)])


def tagged_edges(mesh, tags) -> np.ndarray:
    """Boundary facets carrying any of ``tags``, each once: edges (k, 2) in 2D, faces (k, 3) in 3D.

    ``tags`` is an int, a group name or an iterable of them; ``None`` means the whole
    boundary, found topologically (edges of exactly one triangle), as in
    :func:`femkit.mesh.boundary_nodes`. An edge recorded under several of the tags (generated
    meshes tag every boundary edge with its part and with ``boundary``) is returned once, so
    a flux is never integrated twice over it.
    """
    if tags is None:
        if mesh.dim == 3:
            from ..mesh.faces import boundary_faces_topological

            return boundary_faces_topological(mesh)
        from ..mesh.edges import boundary_edges_topological

        return boundary_edges_topological(mesh)
    if isinstance(tags, (str, int, np.integer)):
        tags = [tags]
    ids = [mesh.tag(t) for t in tags]
    present = set(np.unique(mesh.boundary_tags).tolist())
    missing = [t for t, i in zip(tags, ids) if i not in present]
    if missing:
        what = mesh.facet_name
        raise MeshError(f"no boundary {what}s carry tag(s) {missing}; {what} tags in the mesh: "
                        f"{sorted(present)}")
    sel = mesh.boundary_facets[np.isin(mesh.boundary_tags, ids)]
    _, first = np.unique(np.sort(sel, axis=1), axis=0, return_index=True)
    return sel[np.sort(first)]


def _flux_value(h) -> float:
    try:
        return float(h)
    except (TypeError, ValueError):
        raise InputError(f"Neumann flux must be a number or a callable h(x, y[, z]), got {h!r}") from None


def assemble_neumann(mesh, tags: Union[int, str, Iterable, None], h: Union[float, Callable]) -> np.ndarray:
    """Load vector of the flux ``h`` on the boundary edges with ``tags``.

    Parameters
    ----------
    mesh : Mesh
    tags : int, str, iterable of them, or None (the whole topological boundary); an edge
        under several of the tags counts once
    h : float or callable h(x, y) (h(x, y, z) on a tetrahedral mesh)
        Outward flux ``kappa du/dn``.

    Returns
    -------
    ndarray, shape (n,)
    """
    if mesh.dim == 3:
        return _neumann_faces(mesh, tagged_edges(mesh, tags), h)
    edges = tagged_edges(mesh, tags)
    p0, p1 = mesh.points[edges[:, 0]], mesh.points[edges[:, 1]]
    length = np.hypot(*(p1 - p0).T)
    if callable(h):
        x = p0[:, 0, None] + _S * (p1[:, 0] - p0[:, 0])[:, None]
        y = p0[:, 1, None] + _S * (p1[:, 1] - p0[:, 1])[:, None]
        hq = evaluate_callable(h, x, y, name="h")  # (k, 2)
        w = 0.5 * length[:, None] * hq
        local = np.stack([w @ (1.0 - _S), w @ _S], axis=1)
    else:
        local = np.repeat((0.5 * _flux_value(h) * length)[:, None], 2, axis=1)
    if not np.isfinite(local).all():
        raise InputError("Neumann flux is not finite on some boundary edges")
    return np.bincount(edges.ravel(), weights=local.ravel(), minlength=mesh.n_points)


def _neumann_faces(mesh, faces: np.ndarray, h) -> np.ndarray:
    """``int_face h N_i ds`` on triangular faces (k, 3) by the degree-2 rule ``gauss3``."""
    from .quadrature import get_rule

    p = mesh.points[faces]                                         # (k, 3, 3)
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    if callable(h):
        rule = get_rule("gauss3")
        xyz = np.einsum("qa,kad->dkq", rule.points, p)
        hq = evaluate_callable(h, *xyz, name="h")                   # (k, q)
        local = area[:, None] * ((hq * rule.weights) @ rule.points)
    else:
        local = np.repeat((_flux_value(h) * area / 3.0)[:, None], 3, axis=1)
    if not np.isfinite(local).all():
        raise InputError("Neumann flux is not finite on some boundary faces")
    return np.bincount(faces.ravel(), weights=local.ravel(), minlength=mesh.n_points)


#: The dimension-neutral name of :func:`tagged_edges` (faces on a tetrahedral mesh).
tagged_facets = tagged_edges
