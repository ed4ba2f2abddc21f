"""Global numbering of an element's degrees of freedom on a mesh (the dof map).

Vertex dofs come first and keep the mesh's node numbers (dof ``i`` is node ``i``, so the first
``n_points`` entries of a P2 solution are its vertex values); edge dofs follow, ``n_points + k``
for edge ``k`` of :func:`femkit.mesh.edges.edges` (node pairs sorted, rows sorted
lexicographically: deterministic, vectorised, cached per mesh). Inside a cell the dofs are in
the element's local order (:mod:`femkit.elements.base`: vertices, then edges in VTK order).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.]]), np.array([[0, 1, 2], [0, 2, 3]]))
>>> dm = dof_map(m, "P2")
>>> dm.n_dofs, dm.cells.tolist()
(9, [[0, 1, 2, 4, 7, 5], [0, 2, 3, 5, 8, 6]])
>>> dm.points(m)[4:].tolist()
[[0.5, 0.0], [0.5, 0.5], [0.0, 0.5], [1.0, 0.5], [0.5, 1.0]]
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from ..elements import Element, get_element
from ..mesh.edges import edges
from ..mesh.mesh import LOCAL_EDGES

__all__ = ["DofMap", "dof_map", "local_edge_order"]

_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


@dataclass(frozen=True, eq=False)
class DofMap:
    """The dofs of one element on one mesh.

    Attributes
    ----------
    element : Element
    cells : ndarray, shape (m, n_local), int64
        ``cells[e, i]`` is the global dof of local dof ``i`` of cell ``e``.
    n_dofs : int
        Number of global dofs (``n_points`` for P1, ``n_points + n_edges`` for P2).
    n_vertices : int
        The mesh's node count: dofs ``0 .. n_vertices - 1`` are the vertices.
    edge_nodes : ndarray, shape (E, 2)
        The mesh edge of each edge dof ``n_vertices + k`` (empty for P1).
    """

    element: Element
    cells: np.ndarray
    n_dofs: int
    n_vertices: int
    edge_nodes: np.ndarray

    def points(self, mesh) -> np.ndarray:
        """(n_dofs, dim) coordinates of the dofs: the nodes, then the edge midpoints (the
        interpolation points of Dirichlet data on straight-sided cells)."""
        if not len(self.edge_nodes):
            return mesh.points
        mids = 0.5 * (mesh.points[self.edge_nodes[:, 0]] + mesh.points[self.edge_nodes[:, 1]])
        return np.vstack([mesh.points, mids])

    def interpolate(self, mesh, func) -> np.ndarray:
        """Nodal interpolant of ``func(x, y[, z])`` (vectorised) at the dof points: (n_dofs,)."""
        from .coefficients import evaluate_callable

        pts = self.points(mesh)
        return np.array(evaluate_callable(func, *pts.T, name="function"))


def local_edge_order(dim: int, element: Element) -> np.ndarray:
    """Column index into :func:`femkit.mesh.edges.edges`' ``cell_edges`` of each of the
    element's local edges (the mesh numbers a triangle's edges by the opposite vertex)."""
    mesh_pairs = [frozenset(p) for p in LOCAL_EDGES[dim + 1].tolist()]
    return np.array([mesh_pairs.index(frozenset(p)) for p in element.local_edges.tolist()], dtype=np.intp)


def dof_map(mesh, element: "str | Element" = "P1") -> DofMap:
    """The :class:`DofMap` of ``element`` (a name or an :class:`Element`) on ``mesh``, computed
    once per mesh and element (cached while the mesh lives)."""
    elem = get_element(element, mesh.dim)
    per_mesh = _CACHE.setdefault(mesh, {})
    hit = per_mesh.get(elem.name)
    if hit is None:
        hit = per_mesh[elem.name] = _build(mesh, elem)
    return hit


def _build(mesh, elem: Element) -> DofMap:
    cells = np.asarray(mesh.cells, dtype=np.int64)
    n = mesh.n_points
    if not elem.dofs_per_edge:
        return DofMap(elem, cells, n, n, np.zeros((0, 2), dtype=np.int64))
    edge_nodes, cell_edges = edges(mesh)
    order = local_edge_order(mesh.dim, elem)
    m, nv = cells.shape
    dofs = np.empty((m, nv + len(order)), dtype=np.int64)   # filled column by column: no temporaries
    dofs[:, :nv] = cells
    for k, col in enumerate(order):
        np.add(cell_edges[:, col], n, out=dofs[:, nv + k], dtype=np.int64)
    return DofMap(elem, dofs, n + len(edge_nodes), n, np.asarray(edge_nodes, dtype=np.int64))
