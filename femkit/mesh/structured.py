"""Structured triangulations of a rectangle and tetrahedralisations of a box (no gmsh): the one
grid builder of femkit.

Used by the stress study (Poisson grids), mass-spring cloth scenes (the triangles of a particle
grid), elastic solids and tests.

>>> m = structured_mesh(2, 1, width=2.0)
>>> m.n_points, m.n_triangles, sorted(m.tag_names)
(6, 4, ['bottom', 'left', 'right', 'top'])
>>> b = structured_box(2, 1, 1)
>>> b.dim, b.n_points, b.n_cells, round(float(b.volumes().sum()), 12)
(3, 12, 12, 1.0)
>>> grid_triangles(3, 2).tolist()
[[0, 1, 4], [1, 2, 5], [0, 4, 3], [1, 5, 4]]
"""

from __future__ import annotations

import numpy as np

from .mesh import Mesh

#: Boundary tag ids of :func:`structured_mesh` (``boundary_nodes(mesh, None)`` finds the whole
#: boundary topologically, and case files call it ``boundary``).
SIDES = {"bottom": 1, "right": 2, "top": 3, "left": 4}

#: Boundary face tag ids of :func:`structured_box`; every boundary face also appears once more
#: with the tag ``boundary`` (the convention of :mod:`femkit.mesh.geometries`).
SIDES_3D = {"xmin": 1, "xmax": 2, "ymin": 3, "ymax": 4, "zmin": 5, "zmax": 6, "boundary": 7}

#: The six tetrahedra of the unit cube (Kuhn / Freudenthal): each follows a monotone path
#: from corner (0, 0, 0) to corner (1, 1, 1), one per ordering of the axes. Corner ``c`` is
#: ``(c & 1, c >> 1 & 1, c >> 2 & 1)``; rows are positively oriented (odd orderings have their
#: last two vertices swapped).
KUHN_TETS = np.array([[0, 1, 3, 7], [0, 1, 7, 5], [0, 2, 7, 3], [0, 2, 6, 7], [0, 4, 5, 7],
                      [0, 4, 7, 6]], dtype=np.int64)

__all__ = ["grid_triangles", "structured_mesh", "structured_box", "SIDES", "SIDES_3D", "KUHN_TETS"]


def grid_triangles(nx: int, ny: int, *, diagonal: str = "uniform") -> np.ndarray:
    """Triangles of an ``nx x ny`` grid of *points* numbered row by row (``i + nx j``), CCW.

    ``diagonal="uniform"`` cuts every cell along the same diagonal; ``"alternating"`` flips it on
    every other cell (a criss-cross pattern without a preferred direction).
    """
    if nx < 2 or ny < 2:
        raise ValueError(f"a grid needs at least 2 x 2 points, got {nx} x {ny}")
    if diagonal not in ("uniform", "alternating"):
        raise ValueError(f"diagonal must be 'uniform' or 'alternating', got {diagonal!r}")
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="xy")
    a = (j * nx + i).ravel()
    b, c, d = a + 1, a + nx + 1, a + nx
    if diagonal == "uniform":
        return np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])]).astype(np.int64)
    flip = ((i + j) % 2 == 1).ravel()[:, None]
    t_a = np.where(flip, np.column_stack([a, b, d]), np.column_stack([a, b, c]))
    t_b = np.where(flip, np.column_stack([b, c, d]), np.column_stack([a, c, d]))
    return np.concatenate([t_a, t_b]).astype(np.int64)


def structured_mesh(nx: int, ny: int, width: float = 1.0, height: float = 1.0, *,
                    diagonal: str = "uniform", origin=(0.0, 0.0)) -> Mesh:
    """``nx x ny`` cells of ``[x0, x0 + width] x [y0, y0 + height]``, two triangles per cell.

    The four sides are tagged ``bottom``/``right``/``top``/``left`` (:data:`SIDES`).
    """
    x0, y0 = origin
    xs, ys = np.linspace(x0, x0 + width, nx + 1), np.linspace(y0, y0 + height, ny + 1)
    X, Y = np.meshgrid(xs, ys, indexing="xy")
    pts = np.column_stack([X.ravel(), Y.ravel()])
    tri = grid_triangles(nx + 1, ny + 1, diagonal=diagonal)
    kx, ky = np.arange(nx), np.arange(ny)
    row = nx + 1
    sides = [np.column_stack([kx, kx + 1]),                                  # bottom
             np.column_stack([ky * row + nx, (ky + 1) * row + nx]),          # right
             np.column_stack([ny * row + kx, ny * row + kx + 1]),            # top
             np.column_stack([ky * row, (ky + 1) * row])]                    # left
    edges = np.concatenate(sides).astype(np.int64)
    tags = np.repeat([1, 2, 3, 4], [nx, ny, nx, ny]).astype(np.int32)
    names = dict(SIDES)
    return Mesh(pts, tri, boundary_edges=edges, boundary_tags=tags, tag_names=names)


def structured_box(nx: int, ny: int, nz: int, lengths=(1.0, 1.0, 1.0), *,
                   origin=(0.0, 0.0, 0.0)) -> Mesh:
    """``nx x ny x nz`` hexahedra of a box, each cut into six positively oriented tetrahedra.

    The cut is Kuhn's (:data:`KUHN_TETS`: every tetrahedron contains the diagonal from the
    lowest to the highest corner of its cube), the same in every cube, so the mesh is
    conforming; Bey's red refinement (:func:`femkit.mesh.refine`) of these tetrahedra gives
    the same shapes again. Boundary faces are tagged by side (:data:`SIDES_3D`: ``xmin`` ...
    ``zmax``) and, repeated, ``boundary``; outward oriented. Cells are untagged (0).

    Parameters
    ----------
    nx, ny, nz : number of cells per direction (>= 1)
    lengths : box side lengths ``(lx, ly, lz)``
    origin : lowest corner

    Raises
    ------
    MeshError
        Non-positive counts or lengths.
    """
    from ..errors import MeshError
    from .faces import boundary_faces_topological

    counts = tuple(int(v) for v in (nx, ny, nz))
    if min(counts) < 1 or counts != (nx, ny, nz):
        raise MeshError(f"a box needs at least one cell per direction, got {(nx, ny, nz)}")
    lengths = np.asarray(lengths, dtype=np.float64).reshape(3)
    if not (np.isfinite(lengths).all() and (lengths > 0).all()):
        raise MeshError(f"box lengths must be positive and finite, got {tuple(lengths)}")
    o = np.asarray(origin, dtype=np.float64).reshape(3)
    axes = [np.linspace(o[d], o[d] + lengths[d], counts[d] + 1) for d in range(3)]
    Z, Y, X = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    sx, sy = nx + 1, (nx + 1) * (ny + 1)
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    base = (i + sx * j + sy * k).ravel()
    corner = np.array([(c & 1) + sx * (c >> 1 & 1) + sy * (c >> 2 & 1) for c in range(8)])
    tets = (base[:, None, None] + corner[KUHN_TETS][None]).reshape(-1, 4)

    bf = boundary_faces_topological(Mesh(pts, tets))
    c = pts[bf].mean(axis=1)
    hi = o + lengths
    tol = 1e-9 * lengths.max()
    side = np.select([np.abs(c[:, 0] - o[0]) < tol, np.abs(c[:, 0] - hi[0]) < tol,
                      np.abs(c[:, 1] - o[1]) < tol, np.abs(c[:, 1] - hi[1]) < tol,
                      np.abs(c[:, 2] - o[2]) < tol, np.abs(c[:, 2] - hi[2]) < tol],
                     [1, 2, 3, 4, 5, 6], 0)
    order = np.argsort(side, kind="stable")
    faces = np.concatenate([bf[order], bf[order]])
    tags = np.concatenate([side[order], np.full(len(bf), SIDES_3D["boundary"])]).astype(np.int32)
    return Mesh(pts, tets, boundary_facets=faces, boundary_tags=tags, tag_names=dict(SIDES_3D))
