"""Boundary conditions of a solid: per-component Dirichlet data and surface tractions.

* :class:`Dirichlet` collects prescribed displacements dof by dof, so a clamp (all components),
  a roller or a symmetry plane (one component on a face) and an imposed affine motion are the same
  call with different ``components``.
* :func:`traction_forces` turns a constant (nominal, dead-load) traction on boundary facets --
  edges in 2D, triangles in 3D -- into nodal forces, ``|facet| t / d`` per facet vertex (exact
  for P1 and piecewise-constant ``t``); :func:`body_forces` does the same for a force per unit
  volume (gravity: ``rho g``), ``vol b / (d + 1)`` per element vertex.

>>> import numpy as np
>>> bc = Dirichlet(3, 2).fix([0], components=[0]).fix([1], displacement=[0.1, 0.0])
>>> bc.dofs.tolist(), bc.values.tolist()
([0, 2, 3], [0.0, 0.1, 0.0])
"""

from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from ..errors import InputError

__all__ = ["Dirichlet", "traction_forces", "body_forces", "facet_measures", "tagged_facets",
           "tagged_nodes"]


class Dirichlet:
    """Prescribed displacements, dof by dof (dof ``i*d + a``: node ``i``, component ``a``).

    Parameters
    ----------
    n, dim : number of nodes and space dimension.
    """

    def __init__(self, n: int, dim: int):
        self.n, self.dim = int(n), int(dim)
        self._dofs: list[np.ndarray] = []
        self._vals: list[np.ndarray] = []
        self._merged = None

    def fix(self, nodes, components: Sequence[int] | None = None, displacement=0.0,
            *, rest_positions=None) -> "Dirichlet":
        """Prescribe ``displacement`` on ``components`` (default all) of ``nodes``.

        ``displacement``: a number, a length-``d`` vector, an ``(k, d)`` array (one row per node)
        or a callable ``u(X) -> (k, d)`` of the nodes' rest positions (``rest_positions``
        needed). A dof given twice with different values raises :class:`InputError`.
        Returns ``self`` (calls chain).
        """
        nodes = np.unique(np.asarray(nodes, dtype=np.int64).ravel())
        if nodes.size and (nodes.min() < 0 or nodes.max() >= self.n):
            raise InputError(f"Dirichlet nodes must lie in [0, {self.n - 1}]")
        comps = np.arange(self.dim) if components is None else np.asarray(components, dtype=np.int64)
        if comps.size == 0 or comps.min() < 0 or comps.max() >= self.dim:
            raise InputError(f"Dirichlet components must lie in [0, {self.dim - 1}], got {components!r}")
        if callable(displacement):
            if rest_positions is None:
                raise InputError("a displacement function needs rest_positions")
            u = np.asarray(displacement(np.asarray(rest_positions)[nodes]), dtype=float)
        else:
            u = np.asarray(displacement, dtype=float)
        given = u.shape
        if not np.all(np.isfinite(u)):
            bad = float(u.ravel()[~np.isfinite(u.ravel())][0])
            raise InputError(f"Dirichlet displacement must be finite, got {bad!r} in "
                             f"{u.tolist() if u.size <= 6 else f'an array of shape {given}'}")
        try:
            u = np.broadcast_to(u if u.ndim != 1 or u.shape == (self.dim,) else u[:, None],
                                (len(nodes), self.dim)) if u.ndim <= 1 else u
        except ValueError:  # a vector of the wrong length
            pass
        if u.shape != (len(nodes), self.dim):
            raise InputError(f"Dirichlet displacement must be a number, a {self.dim}-vector or "
                             f"one row per node ({len(nodes)} x {self.dim}); got shape {given}")
        dofs = (nodes[:, None] * self.dim + comps[None, :]).ravel()
        self._dofs.append(dofs)
        self._vals.append(u[:, comps].ravel())
        self._merged = None
        self._merge()
        return self

    def _merge(self) -> tuple[np.ndarray, np.ndarray]:
        if self._merged is None:
            dofs = np.concatenate(self._dofs) if self._dofs else np.zeros(0, np.int64)
            vals = np.concatenate(self._vals) if self._vals else np.zeros(0)
            order = np.lexsort((vals, dofs))
            dofs, vals = dofs[order], vals[order]
            clash = np.flatnonzero((dofs[1:] == dofs[:-1]) & (vals[1:] != vals[:-1]))
            if len(clash):
                k = int(dofs[clash[0]])
                self._dofs.pop(), self._vals.pop()
                raise InputError(f"dof {k} (node {k // self.dim}, component {k % self.dim}) "
                                 f"prescribed twice: {float(vals[clash[0]]):g} and {float(vals[clash[0] + 1]):g}")
            keep = np.ones(len(dofs), dtype=bool)
            keep[1:] = dofs[1:] != dofs[:-1]
            self._merged = (dofs[keep], vals[keep])
        return self._merged

    @property
    def dofs(self) -> np.ndarray:
        """Prescribed dofs, sorted."""
        return self._merge()[0]

    @property
    def values(self) -> np.ndarray:
        """Prescribed displacements in the order of :attr:`dofs`."""
        return self._merge()[1]

    def free(self) -> np.ndarray:
        """The dofs not prescribed."""
        mask = np.ones(self.n * self.dim, dtype=bool)
        mask[self.dofs] = False
        return np.flatnonzero(mask)


def facet_measures(points, facets) -> np.ndarray:
    """Lengths (2D edges) or areas (3D triangles) of boundary facets ``(k, d)``."""
    P = np.asarray(points, dtype=float)
    f = np.asarray(facets, dtype=np.int64)
    e1 = P[f[:, 1]] - P[f[:, 0]]
    if P.shape[1] == 2:
        return np.linalg.norm(e1, axis=1)
    return 0.5 * np.linalg.norm(np.cross(e1, P[f[:, 2]] - P[f[:, 0]]), axis=1)


def traction_forces(points, facets, traction) -> np.ndarray:
    """Nodal forces ``(n, d)`` of a traction ``t`` (a ``d``-vector or one per facet) on
    ``facets``, measured on the rest configuration: P1 facets ``(k, d)`` (vertex indices of
    boundary edges/triangles) get ``|facet| t / d`` to each vertex; quadratic facets ``(k, 3)``
    in 2D or ``(k, 6)`` in 3D (:func:`femkit.solids.quadratic.facet_nodes`: vertices, then edge
    midpoints) the consistent shares of :func:`femkit.solids.quadratic.facet_load_weights`."""
    P = np.asarray(points, dtype=float)
    n, d = P.shape
    f = np.asarray(facets, dtype=np.int64)
    width = f.shape[1] if f.ndim == 2 and f.shape[1] == (3 if d == 2 else 6) else d
    f = f.reshape(-1, width)
    t = np.broadcast_to(np.asarray(traction, dtype=float), (len(f), d))
    if not np.all(np.isfinite(t)):
        raise InputError("traction must be finite")
    out = np.zeros((n, d))
    if width == d:                                  # P1: the same arithmetic as ever
        w = facet_measures(P, f)[:, None] * t / d
        for a in range(d):
            out[:, a] = np.bincount(f.ravel(), weights=np.repeat(w[:, a], d), minlength=n)
        return out
    from .quadratic import facet_load_weights

    w = facet_measures(P, f[:, :d])[:, None] * t
    share = facet_load_weights(d)
    for a in range(d):
        out[:, a] = np.bincount(f.ravel(), weights=(w[:, a, None] * share).ravel(), minlength=n)
    return out


def body_forces(body, force_density: Callable | np.ndarray) -> np.ndarray:
    """Nodal forces ``(n, d)`` of a force per unit volume ``b`` (a ``d``-vector, or one per
    element): P1 ``vol b / (d + 1)`` to each vertex, P2 the integrals of the basis functions
    (:func:`femkit.solids.quadratic.cell_load_weights`). Gravity is ``b = rho g``
    (``body.density()[:, None] * g``)."""
    m, d = body.rest.n_cells, body.dim
    b = np.broadcast_to(np.asarray(force_density, dtype=float), (m, d))
    cells = body.rest.cells
    out = np.zeros((body.n, d))
    if cells.shape[1] == d + 1:                     # P1: the same arithmetic as ever
        w = body.rest.volumes[:, None] * b / (d + 1)
        for a in range(d):
            out[:, a] = np.bincount(cells.ravel(), weights=np.repeat(w[:, a], d + 1),
                                    minlength=body.n)
        return out
    from .quadratic import cell_load_weights

    share = cell_load_weights(d)
    w = body.rest.volumes[:, None] * b
    for a in range(d):
        out[:, a] = np.bincount(cells.ravel(), weights=(w[:, a, None] * share).ravel(),
                                minlength=body.n)
    return out


def tagged_facets(mesh, tags) -> np.ndarray:
    """Boundary facets of ``mesh`` (a :class:`femkit.mesh.Mesh`) carrying any of ``tags``
    (names or numbers). An unknown name raises :class:`~femkit.errors.MeshError` listing the
    known groups; tags that select no facet raise :class:`InputError`."""
    names = [tags] if isinstance(tags, (str, int, np.integer)) else list(tags)
    ids = [mesh.tag(t) for t in names]
    sel = np.isin(mesh.boundary_tags, ids)
    if not sel.any():
        raise InputError(f"no boundary facets tagged {', '.join(map(str, names))}")
    return mesh.boundary_facets[sel]


def tagged_nodes(mesh, tags) -> np.ndarray:
    """The nodes of :func:`tagged_facets` (sorted, unique)."""
    return np.unique(tagged_facets(mesh, tags))
