"""Quadratic (P2) elastic elements: rest data at quadrature points, facet nodes, nodal loads.

A P2 body's nodes are the mesh's vertices followed by its edge midpoints, numbered by
:func:`femkit.fem.dofs.dof_map` (the element's local order: vertices, then edges in VTK order, so
a cell's nodes are a VTK quadratic triangle (22) or tetrahedron (24)). On a straight-sided cell
the deformation gradient ``F = sum_n x_n g_n^T`` of a P2 displacement is linear, so it is
evaluated at the points of a quadrature rule exact for the element's stiffness (degree 2:
3 points on a triangle, 4 on a tetrahedron; :func:`femkit.fem.quadrature.rule_for_degree`), each
point with its own SVD, stress and PSD-projected ``dP/dF`` (:func:`femkit.elements.compiled.
element_pass_points`). The linear material is then integrated exactly: P2 linear elasticity
equals scikit-fem's ``linear_elasticity`` on ``ElementVector(ElementTriP2())`` /
``ElementVector(ElementTetP2())`` (``tests/solids/test_quadratic.py``).

Loads on P2 nodes are the consistent ones: a constant traction on a quadratic edge gives
``|e| t (1/6, 1/6, 2/3)`` (ends, middle), on a quadratic triangle ``|f| t / 3`` to each edge
node and nothing to its vertices; a constant body force gives a triangle's edge nodes
``|T| b / 3`` (vertices 0) and a tetrahedron's vertices ``-|T| b / 20``, edge nodes
``|T| b / 5`` (the integrals of the basis functions).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> r = quadratic_rest(Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]])))
>>> r.cells.tolist(), r.n_points, round(float(r.weights.sum()), 12)
([[0, 1, 2, 3, 5, 4]], 3, 0.5)
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .kinematics import RestShape, rest_shape

__all__ = ["quadratic_rest", "facet_nodes", "facet_load_weights", "cell_load_weights"]


def quadratic_rest(mesh, element: str = "P2") -> RestShape:
    """Rest data of the P2 elements of ``mesh`` (a :class:`femkit.mesh.Mesh`).

    Returns a :class:`~femkit.solids.kinematics.RestShape` whose ``cells`` are the P2 node
    lists ``(m, 6 | 10)``, ``gradients`` the physical shape-function gradients at each cell's
    quadrature points ``(m q, nv, d)`` (row ``e q + k``), ``weights`` the quadrature weight times
    the cell's volume ``(m q,)`` and ``n_points`` ``= q``; ``volumes``, ``dm_inv`` as for P1.

    Raises
    ------
    DegenerateMeshError
        Inverted or zero-volume cells (as :func:`~femkit.solids.kinematics.rest_shape`).
    """
    from ..fem.dofs import dof_map
    from ..fem.quadrature import rule_for_degree

    p1 = rest_shape(mesh.points, mesh.cells)
    dofs = dof_map(mesh, element)
    elem = dofs.element
    rule = rule_for_degree(elem.stiffness_degree, mesh.dim)
    dl = elem.lambda_gradients(rule.points)                   # (q, nv, d+1)
    # physical gradients: dphi/dlambda @ G, G (m, d+1, d) the P1 (barycentric) gradients
    grads = np.einsum("qna,mab->mqnb", dl, p1.gradients).reshape(-1, elem.n_dofs, mesh.dim)
    weights = (p1.volumes[:, None] * rule.weights[None, :]).reshape(-1)
    return RestShape(np.ascontiguousarray(dofs.cells), p1.dm_inv, p1.volumes,
                     np.ascontiguousarray(grads), weights=np.ascontiguousarray(weights),
                     n_points=len(rule.weights), element=elem.name,
                     n_nodes=int(dofs.n_dofs))


def node_positions(mesh, element: str = "P2") -> np.ndarray:
    """Rest positions of the nodes of ``element`` on ``mesh``: vertices, then edge midpoints."""
    from ..fem.dofs import dof_map

    return np.ascontiguousarray(dof_map(mesh, element).points(mesh))


def facet_nodes(mesh, facets, element: str = "P2") -> np.ndarray:
    """The P2 nodes of boundary ``facets`` (vertex triples or pairs of ``mesh``): ``(k, 3)``
    for edges (ends, then the midpoint) or ``(k, 6)`` for triangles (vertices, then the edges
    (0,1), (1,2), (0,2)), node numbers of :func:`femkit.fem.dofs.dof_map`."""
    from ..fem.dofs import dof_map

    dofs = dof_map(mesh, element)
    f = np.asarray(facets, dtype=np.int64).reshape(-1, mesh.dim)
    pairs = [(0, 1)] if mesh.dim == 2 else [(0, 1), (1, 2), (0, 2)]
    n = np.int64(mesh.n_points)
    en = np.asarray(dofs.edge_nodes, dtype=np.int64)
    keys = en[:, 0] * n + en[:, 1]                            # sorted (rows lexicographic)
    cols = []
    for a, b in pairs:
        lo, hi = np.minimum(f[:, a], f[:, b]), np.maximum(f[:, a], f[:, b])
        want = lo * n + hi
        pos = np.searchsorted(keys, want)
        pos = np.minimum(pos, len(keys) - 1)
        if len(want) and not np.all(keys[pos] == want):
            raise InputError("a boundary facet's edge is not an edge of the mesh")
        cols.append(dofs.n_vertices + pos)
    return np.concatenate([f, np.stack(cols, axis=1)], axis=1)


def facet_load_weights(dim: int) -> np.ndarray:
    """Share of ``|facet| t`` (a constant traction) each P2 facet node receives, in the order
    of :func:`facet_nodes`."""
    if dim == 2:
        return np.array([1.0, 1.0, 4.0]) / 6.0
    return np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0]) / 3.0


def cell_load_weights(dim: int) -> np.ndarray:
    """Share of ``|T| b`` (a constant body force) each P2 cell node receives: the integrals of
    its basis functions over the cell, divided by ``|T|``."""
    if dim == 2:
        return np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0]) / 3.0
    return np.array([-1.0] * 4 + [4.0] * 6) / 20.0
