"""Uniform red refinement (every triangle into four; nested meshes).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(points=np.array([[0., 0.], [1., 0.], [0., 1.]]), triangles=np.array([[0, 1, 2]]))
>>> f = refine(m, levels=2)
>>> f.n_triangles, f.n_points, float(f.areas().sum())
(16, 15, 0.5)
"""

from __future__ import annotations

import numpy as np

from .edges import boundary_edge_ids, edges
from .mesh import Mesh


def refine_once(mesh: Mesh) -> tuple[Mesh, np.ndarray]:
    """One level of red refinement, and the coarse edges whose midpoints are the new nodes.

    Returns ``(fine, edge_nodes)``: fine node ``n + e`` is the midpoint of coarse edge
    ``edge_nodes[e]`` (:func:`edges` order), so a nested prolongation needs no second edge search
    (:class:`femkit.mesh.hierarchy.MeshHierarchy`).
    """
    n = mesh.n_points
    edge_nodes, tri_edges = edges(mesh)
    mid = mesh.points[edge_nodes].mean(axis=1)
    points = np.vstack([mesh.points, mid])
    t = mesh.triangles
    m0, m1, m2 = (n + tri_edges[:, k] for k in range(3))
    v0, v1, v2 = t[:, 0], t[:, 1], t[:, 2]
    # children are counter-clockwise when the parent is; the four of a parent are contiguous
    children = np.stack([
        np.stack([v0, m2, m1], axis=1),
        np.stack([m2, v1, m0], axis=1),
        np.stack([m1, m0, v2], axis=1),
        np.stack([m0, m1, m2], axis=1),
    ], axis=1).reshape(-1, 3)
    cell_tags = np.repeat(mesh.cell_tags, 4)

    be = mesh.boundary_edges
    if len(be):
        bm = n + boundary_edge_ids(mesh, edge_nodes)
        new_be = np.stack([np.stack([be[:, 0], bm], axis=1),
                           np.stack([bm, be[:, 1]], axis=1)], axis=1).reshape(-1, 2)
        new_bt = np.repeat(mesh.boundary_tags, 2)
    else:
        new_be, new_bt = be, mesh.boundary_tags
    fine = Mesh(points=points, triangles=children, cell_tags=cell_tags,
                boundary_edges=new_be, boundary_tags=new_bt, tag_names=mesh.tag_names)
    return fine, edge_nodes


def refine(mesh: Mesh, levels: int = 1) -> Mesh:
    """Uniform red refinement: each triangle into four by its edge midpoints, ``levels`` times.

    Nested: the coarse nodes are the first ``n`` nodes of the fine mesh (in the same order),
    then one new node per coarse edge in :func:`edges` order. Children ``4t .. 4t+3`` come
    from coarse triangle ``t`` and inherit its cell tag; each tagged boundary edge becomes two
    edges (same direction) with its tag. Orientation is preserved. Whether the refined mesh
    fits in memory is checked by the application before it calls this
    (``femkit.case.cost.check_mesh_fits``).
    """
    if int(levels) != levels or levels < 0:
        raise ValueError(f"levels must be a non-negative integer, got {levels!r}")
    for _ in range(int(levels)):
        mesh, _ = refine_once(mesh)
    return mesh
