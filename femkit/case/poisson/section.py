"""A plane section of a tetrahedral mesh: the triangles a person looks at in a 3D run's PNG.

The plane ``z = z0`` cuts a tetrahedron in a triangle (three of its edges cross the plane) or a
quadrilateral (four edges; split into two triangles). Every crossing point lies on a mesh edge,
so a P1 field restricted to the plane is the linear interpolation of its two end values: the
section of the field is exact, not resampled. Vectorised over tetrahedra (no Python loop).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]), np.array([[0, 1, 2, 3]]))
>>> s = plane_section(m, 0.5)
>>> s.points.shape, s.triangles.tolist(), s.cells.tolist()
((3, 2), [[0, 1, 2]], [0])
>>> s.interpolate(np.array([0., 0, 0, 2])).tolist()
[1.0, 1.0, 1.0]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PlaneSection", "plane_section"]


@dataclass(frozen=True)
class PlaneSection:
    """The triangles of the plane ``z = z0`` inside a tetrahedral mesh.

    Attributes
    ----------
    z : float
        The height of the plane.
    points : (p, 2) array
        ``(x, y)`` of the crossing points, one per cut mesh edge.
    triangles : (t, 3) array
        Section triangles (indices into ``points``).
    cells : (t,) array
        The tetrahedron each section triangle lies in (for cell data such as indicators).
    edge_nodes : (p, 2) array
        The mesh nodes at the ends of each crossing point's edge.
    weights : (p,) array
        The weight of ``edge_nodes[:, 1]`` in the linear interpolation.
    """

    z: float
    points: np.ndarray
    triangles: np.ndarray
    cells: np.ndarray
    edge_nodes: np.ndarray
    weights: np.ndarray

    def interpolate(self, u: np.ndarray) -> np.ndarray:
        """The P1 nodal field ``u`` at the section's points (exact on the plane)."""
        u = np.asarray(u, dtype=np.float64)
        a, b = u[self.edge_nodes[:, 0]], u[self.edge_nodes[:, 1]]
        return (1.0 - self.weights) * a + self.weights * b


def plane_section(mesh, z: float) -> PlaneSection:
    """The section of the tetrahedral ``mesh`` by the plane ``z``; empty arrays when the plane
    misses it. A node lying exactly on the plane counts as above it (no degenerate pieces)."""
    from ...mesh.edges import edges

    edge_nodes, cell_edges = edges(mesh)
    s = mesh.points[:, 2] - float(z)
    above = s >= 0
    sa, sb = s[edge_nodes[:, 0]], s[edge_nodes[:, 1]]
    crossing = above[edge_nodes[:, 0]] != above[edge_nodes[:, 1]]
    index = np.full(len(edge_nodes), -1, dtype=np.int64)
    index[crossing] = np.arange(int(crossing.sum()))
    cut = edge_nodes[crossing]
    w = sa[crossing] / (sa[crossing] - sb[crossing])
    p0, p1 = mesh.points[cut[:, 0], :2], mesh.points[cut[:, 1], :2]
    xy = (1.0 - w)[:, None] * p0 + w[:, None] * p1

    local = index[cell_edges]                              # (m, 6): section point or -1
    count = (local >= 0).sum(axis=1)
    tri_cells = np.flatnonzero(count == 3)
    quad_cells = np.flatnonzero(count == 4)
    # the crossing points of each cut tetrahedron first (a stable sort keeps their order)
    order = np.argsort(local < 0, axis=1, kind="stable")
    first = np.take_along_axis(local, order, axis=1)
    tris = first[tri_cells, :3]
    quads = first[quad_cells, :4]
    if len(quads):  # order the four corners by angle around their centre, then split in two
        c = xy[quads].mean(axis=1, keepdims=True)
        d = xy[quads] - c
        quads = np.take_along_axis(quads, np.argsort(np.arctan2(d[..., 1], d[..., 0]), axis=1),
                                   axis=1)
    triangles = np.concatenate([tris, quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]).astype(np.int64)
    triangles = triangles.reshape(-1, 3)
    cells = np.concatenate([tri_cells, quad_cells, quad_cells]).astype(np.int64)
    # pieces of zero area (a tetrahedron touching the plane in an edge or a node) are dropped
    a, b, c = (xy[triangles[:, k]] for k in range(3))
    area2 = np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    keep = area2 > 1e-12 * max(float(area2.max(initial=0.0)), 1e-300)
    return PlaneSection(float(z), xy, triangles[keep], cells[keep], cut, w)
