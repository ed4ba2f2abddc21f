"""The mesh record every femkit module shares: P1 triangles (2D) or tetrahedra (3D).

A :class:`Mesh` is plain arrays, so a user can build one from their own data::

    >>> import numpy as np
    >>> from femkit.mesh import Mesh
    >>> m = Mesh(points=np.array([[0., 0.], [1., 0.], [0., 1.]]),
    ...          triangles=np.array([[0, 1, 2]]))
    >>> m.dim, m.n_points, m.n_triangles
    (2, 3, 1)
    >>> float(m.areas()[0])
    0.5

The same record holds tetrahedra; the width of ``cells`` decides the dimension::

    >>> t = Mesh(np.eye(4, 3)[[3, 0, 1, 2]], np.array([[0, 1, 2, 3]]))
    >>> t.dim, t.n_cells, round(float(t.volumes()[0]), 6)
    (3, 1, 0.166667)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MeshError

#: Name of a cell, of its volume and of a boundary facet, per dimension (for messages).
CELL_NAME = {2: "triangle", 3: "tetrahedron"}
CELLS_NAME = {2: "triangles", 3: "tetrahedra"}
FACET_NAME = {2: "edge", 3: "face"}

_ALIASES = {"triangles": ("cells", 2), "tetrahedra": ("cells", 3),
            "boundary_edges": ("boundary_facets", 2), "boundary_faces": ("boundary_facets", 3)}


def signed_volumes(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Signed area (triangles) or volume (tetrahedra) of each cell, positive when oriented.

    Triangles are positive when counter-clockwise, tetrahedra when
    ``det[x1 - x0, x2 - x0, x3 - x0] > 0``.
    """
    p0 = points[cells[:, 0]]
    if cells.shape[1] == 3:
        b, c = points[cells[:, 1]] - p0, points[cells[:, 2]] - p0
        return 0.5 * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
    a, b, c = (points[cells[:, k]] - p0 for k in (1, 2, 3))
    return np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0



#: Local edges of a triangle (edge k opposite vertex k) and of a tetrahedron (Bey's order:
#: 01, 02, 03, 12, 13, 23).
LOCAL_EDGES = {3: np.array([[1, 2], [2, 0], [0, 1]]),
               4: np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]])}


@dataclass(frozen=True, eq=False, init=False)
class Mesh:
    """P1 simplex mesh: triangles in 2D, tetrahedra in 3D.

    Parameters
    ----------
    points : (n, dim) array_like of float
        Node coordinates. A 3-column array with triangles drops z (a planar mesh).
    cells : (m, dim + 1) array_like of int
        Node indices of each cell: 3 columns = triangles (counter-clockwise), 4 = tetrahedra
        (positively oriented). Aliases: ``triangles=`` (2D), ``tetrahedra=`` (3D).
    cell_tags : (m,) array_like of int, optional
        Physical tag of each cell (0 = untagged).
    boundary_facets : (k, dim) array_like of int, optional
        Node indices of tagged boundary facets: edges in 2D, triangular faces in 3D. Aliases:
        ``boundary_edges=`` (2D), ``boundary_faces=`` (3D).
    boundary_tags : (k,) array_like of int, optional
        Physical tag of each boundary facet.
    tag_names : dict[str, int], optional
        Physical group names -> tag numbers (cells and facets share one namespace).

    Raises
    ------
    MeshError
        Arrays of the wrong shape, or an alias of the wrong dimension.
    """

    points: np.ndarray
    cells: np.ndarray
    cell_tags: np.ndarray
    boundary_facets: np.ndarray
    boundary_tags: np.ndarray
    tag_names: dict

    def __init__(self, points, cells=None, cell_tags=None, boundary_facets=None,
                 boundary_tags=None, tag_names=None, **aliases) -> None:
        given = {"cells": cells, "boundary_facets": boundary_facets}
        want_dim = None
        for key, value in aliases.items():
            if key not in _ALIASES:
                raise TypeError(f"Mesh() got an unexpected keyword argument {key!r}")
            target, dim = _ALIASES[key]
            if given[target] is not None:
                raise TypeError(f"Mesh() got both {target!r} and its alias {key!r}")
            if want_dim is not None and want_dim != dim:
                raise MeshError(f"Mesh() got {key!r} (a {dim}D name) with a {want_dim}D one")
            given[target], want_dim = value, dim
        if given["cells"] is None:
            raise TypeError("Mesh() needs cells (or triangles= / tetrahedra=)")
        cl = np.ascontiguousarray(given["cells"], dtype=np.int64)
        if cl.ndim != 2 or cl.shape[1] not in (3, 4):
            raise MeshError(f"cells must have shape (m, 3) (triangles) or (m, 4) (tetrahedra), "
                       f"got {cl.shape}")
        dim = cl.shape[1] - 1
        if want_dim is not None and want_dim != dim:
            alias = [k for k in aliases if _ALIASES[k][0] == "cells"]
            what = alias[0] if alias else next(iter(aliases))
            raise MeshError(f"{what}= is for {want_dim}D meshes but the cells have {dim + 1} "
                       f"columns (a {dim}D mesh)")
        pts = np.ascontiguousarray(points, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] < dim or pts.shape[1] > 3:
            raise MeshError(f"points of a {dim}D mesh must have shape (n, {dim}), got {pts.shape}")
        pts = np.ascontiguousarray(pts[:, :dim])
        ct = (np.zeros(len(cl), np.int32) if cell_tags is None
              else np.ascontiguousarray(cell_tags, dtype=np.int32).reshape(-1))
        bf = (np.zeros((0, dim), np.int64) if given["boundary_facets"] is None
              else np.ascontiguousarray(given["boundary_facets"], dtype=np.int64))
        if bf.size == 0:
            bf = bf.reshape(0, dim)
        if bf.ndim != 2 or bf.shape[1] != dim:
            raise MeshError(f"boundary facets of a {dim}D mesh must have shape (k, {dim}), "
                       f"got {bf.shape}")
        bt = (np.zeros(len(bf), np.int32) if boundary_tags is None
              else np.ascontiguousarray(boundary_tags, dtype=np.int32).reshape(-1))
        if len(ct) != len(cl):
            raise MeshError(f"cell_tags must have one entry per {CELL_NAME[dim]} "
                       f"({len(ct)} for {len(cl)})")
        if len(bt) != len(bf):
            raise MeshError(f"boundary_tags must have one entry per boundary {FACET_NAME[dim]} "
                       f"({len(bt)} for {len(bf)})")
        for name, value in (("points", pts), ("cells", cl), ("cell_tags", ct),
                            ("boundary_facets", bf), ("boundary_tags", bt),
                            ("tag_names", dict(tag_names or {}))):
            object.__setattr__(self, name, value)

    # ---- dimension-generic interface ------------------------------------------------------
    @property
    def dim(self) -> int:
        """Spatial dimension: 2 (triangles) or 3 (tetrahedra)."""
        return int(self.cells.shape[1]) - 1

    @property
    def cell_name(self) -> str:
        """``"triangle"`` or ``"tetrahedron"``."""
        return CELL_NAME[self.dim]

    @property
    def facet_name(self) -> str:
        """``"edge"`` or ``"face"``."""
        return FACET_NAME[self.dim]

    @property
    def n_points(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_cells(self) -> int:
        return int(self.cells.shape[0])

    def signed_volumes(self) -> np.ndarray:
        """Signed area (2D) or volume (3D) of each cell, positive when oriented."""
        return signed_volumes(self.points, self.cells)

    def volumes(self) -> np.ndarray:
        """Area (2D) or volume (3D) of each cell."""
        return np.abs(self.signed_volumes())

    def centroids(self) -> np.ndarray:
        """Barycentre of each cell, shape (m, dim)."""
        return self.points[self.cells].mean(axis=1)

    def tag(self, name_or_id) -> int:
        """Resolve a physical group name or number to its tag number."""
        if isinstance(name_or_id, (int, np.integer)):
            return int(name_or_id)
        try:
            return int(self.tag_names[name_or_id])
        except KeyError:
            raise MeshError(
                f"mesh has no physical group {name_or_id!r}; known groups: "
                f"{', '.join(sorted(self.tag_names)) or '(none)'}"
            ) from None

    # ---- names of one dimension (backward compatible) -------------------------------------
    def _need(self, dim: int, what: str) -> None:
        if self.dim != dim:
            raise MeshError(f"{what} exists on {dim}D meshes ({CELLS_NAME[dim]}) only; this "
                            f"mesh is {self.dim}D ({self.n_cells} {CELLS_NAME[self.dim]})")

    @property
    def triangles(self) -> np.ndarray:
        """The cells of a 2D mesh (``MeshError`` on a 3D one)."""
        self._need(2, "mesh.triangles")
        return self.cells

    @property
    def n_triangles(self) -> int:
        self._need(2, "mesh.n_triangles")
        return self.n_cells

    @property
    def boundary_edges(self) -> np.ndarray:
        """The boundary facets of a 2D mesh (``MeshError`` on a 3D one)."""
        self._need(2, "mesh.boundary_edges")
        return self.boundary_facets

    def signed_areas(self) -> np.ndarray:
        """Signed area of each triangle (positive when counter-clockwise); 2D only."""
        self._need(2, "mesh.signed_areas()")
        return self.signed_volumes()

    def areas(self) -> np.ndarray:
        """Area of each triangle; 2D only."""
        self._need(2, "mesh.areas()")
        return self.volumes()

    @property
    def tetrahedra(self) -> np.ndarray:
        """The cells of a 3D mesh (``MeshError`` on a 2D one)."""
        self._need(3, "mesh.tetrahedra")
        return self.cells

    @property
    def boundary_faces(self) -> np.ndarray:
        """The boundary facets of a 3D mesh (``MeshError`` on a 2D one)."""
        self._need(3, "mesh.boundary_faces")
        return self.boundary_facets

    def __repr__(self) -> str:
        return (f"Mesh({self.n_points} points, {self.n_cells} {CELLS_NAME[self.dim]}, "
                f"{len(self.boundary_facets)} tagged boundary {self.facet_name}s, "
                f"groups={sorted(self.tag_names)})")
