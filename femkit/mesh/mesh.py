"""The mesh record every femkit module shares.

A :class:`Mesh` is plain arrays, so a user can build one from their own data::

    >>> import numpy as np
    >>> from femkit.mesh import Mesh
    >>> m = Mesh(points=np.array([[0., 0.], [1., 0.], [0., 1.]]),
    ...          triangles=np.array([[0, 1, 2]]))
    >>> m.n_points, m.n_triangles
    (3, 1)
    >>> float(m.areas()[0])
    0.5
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True, eq=False)
class Mesh:
    """P1 triangle mesh.

    Attributes
    ----------
    points : (n, 2) float64
        Node coordinates.
    triangles : (m, 3) int64
        Node indices of each triangle, counter-clockwise.
    cell_tags : (m,) int32
        Physical tag of each triangle (0 = untagged).
    boundary_edges : (k, 2) int64
        Node indices of tagged boundary edges.
    boundary_tags : (k,) int32
        Physical tag of each boundary edge.
    tag_names : dict[str, int]
        Physical group names -> tag numbers (both cells and edges).
    """

    points: np.ndarray
    triangles: np.ndarray
    cell_tags: np.ndarray | None = None
    boundary_edges: np.ndarray | None = None
    boundary_tags: np.ndarray | None = None
    tag_names: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        pts = np.ascontiguousarray(self.points, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] not in (2, 3):
            raise ValueError(f"points must have shape (n, 2), got {pts.shape}")
        pts = np.ascontiguousarray(pts[:, :2])
        tri = np.ascontiguousarray(self.triangles, dtype=np.int64)
        if tri.ndim != 2 or tri.shape[1] != 3:
            raise ValueError(f"triangles must have shape (m, 3), got {tri.shape}")
        ct = (np.zeros(len(tri), np.int32) if self.cell_tags is None
              else np.ascontiguousarray(self.cell_tags, dtype=np.int32))
        be = (np.zeros((0, 2), np.int64) if self.boundary_edges is None
              else np.ascontiguousarray(self.boundary_edges, dtype=np.int64).reshape(-1, 2))
        bt = (np.zeros(len(be), np.int32) if self.boundary_tags is None
              else np.ascontiguousarray(self.boundary_tags, dtype=np.int32))
        if len(ct) != len(tri):
            raise ValueError("cell_tags must have one entry per triangle")
        if len(bt) != len(be):
            raise ValueError("boundary_tags must have one entry per boundary edge")
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "triangles", tri)
        object.__setattr__(self, "cell_tags", ct)
        object.__setattr__(self, "boundary_edges", be)
        object.__setattr__(self, "boundary_tags", bt)
        object.__setattr__(self, "tag_names", dict(self.tag_names))

    @property
    def n_points(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_triangles(self) -> int:
        return int(self.triangles.shape[0])

    def signed_areas(self) -> np.ndarray:
        """Signed area of each triangle (positive when counter-clockwise)."""
        p = self.points
        a, b, c = p[self.triangles[:, 0]], p[self.triangles[:, 1]], p[self.triangles[:, 2]]
        return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))

    def areas(self) -> np.ndarray:
        """Area of each triangle."""
        return np.abs(self.signed_areas())

    def centroids(self) -> np.ndarray:
        """Barycentre of each triangle, shape (m, 2)."""
        return self.points[self.triangles].mean(axis=1)

    def tag(self, name_or_id) -> int:
        """Resolve a physical group name or number to its tag number."""
        if isinstance(name_or_id, (int, np.integer)):
            return int(name_or_id)
        try:
            return int(self.tag_names[name_or_id])
        except KeyError:
            from ..errors import MeshError
            raise MeshError(
                f"mesh has no physical group {name_or_id!r}; known groups: "
                f"{', '.join(sorted(self.tag_names)) or '(none)'}"
            ) from None

    def __repr__(self) -> str:
        return (f"Mesh({self.n_points} points, {self.n_triangles} triangles, "
                f"{len(self.boundary_edges)} tagged boundary edges, groups={sorted(self.tag_names)})")
