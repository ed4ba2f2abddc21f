"""Neumann flux ``kappa du/dn = h`` on tagged boundary edges: ``F_i += int_edge h N_i ds``.

Two-point Gauss rule per edge (exact for ``h`` linear along the edge times P1).

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
    """Boundary edges (k, 2) carrying any of ``tags``, each edge once.

    ``tags`` is an int, a group name or an iterable of them; ``None`` means the whole
    boundary, found topologically (edges of exactly one triangle), as in
    :func:`femkit.mesh.boundary_nodes`. An edge recorded under several of the tags (generated
    meshes tag every boundary edge with its part and with ``boundary``) is returned once, so
    a flux is never integrated twice over it.
    """
    if tags is None:
        from ..mesh.edges import boundary_edges_topological

        return boundary_edges_topological(mesh)
    if isinstance(tags, (str, int, np.integer)):
        tags = [tags]
    ids = [mesh.tag(t) for t in tags]
    present = set(np.unique(mesh.boundary_tags).tolist())
    missing = [t for t, i in zip(tags, ids) if i not in present]
    if missing:
        raise MeshError(f"no boundary edges carry tag(s) {missing}; edge tags in the mesh: {sorted(present)}")
    sel = mesh.boundary_edges[np.isin(mesh.boundary_tags, ids)]
    _, first = np.unique(np.sort(sel, axis=1), axis=0, return_index=True)
    return sel[np.sort(first)]


def assemble_neumann(mesh, tags: Union[int, str, Iterable, None], h: Union[float, Callable]) -> np.ndarray:
    """Load vector of the flux ``h`` on the boundary edges with ``tags``.

    Parameters
    ----------
    mesh : Mesh
    tags : int, str, iterable of them, or None (the whole topological boundary); an edge
        under several of the tags counts once
    h : float or callable h(x, y)
        Outward flux ``kappa du/dn``.

    Returns
    -------
    ndarray, shape (n,)
    """
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
        try:
            val = float(h)
        except (TypeError, ValueError):
            raise InputError(f"Neumann flux must be a number or a callable h(x, y), got {h!r}") from None
        local = np.repeat((0.5 * val * length)[:, None], 2, axis=1)
    if not np.isfinite(local).all():
        raise InputError("Neumann flux is not finite on some boundary edges")
    return np.bincount(edges.ravel(), weights=local.ravel(), minlength=mesh.n_points)
