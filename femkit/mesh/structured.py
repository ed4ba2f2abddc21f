"""Structured triangulations of a rectangle (no gmsh): the one grid builder of femkit.

Used by the stress study (Poisson grids), mass-spring cloth scenes (the triangles of a particle
grid) and tests.

>>> m = structured_mesh(2, 1, width=2.0)
>>> m.n_points, m.n_triangles, sorted(m.tag_names)
(6, 4, ['bottom', 'left', 'right', 'top'])
>>> grid_triangles(3, 2).tolist()
[[0, 1, 4], [1, 2, 5], [0, 4, 3], [1, 5, 4]]
"""

from __future__ import annotations

import numpy as np

from .mesh import Mesh

#: Boundary tag ids of :func:`structured_mesh` (``boundary_nodes(mesh, None)`` finds the whole
#: boundary topologically, and case files call it ``boundary``).
SIDES = {"bottom": 1, "right": 2, "top": 3, "left": 4}

__all__ = ["grid_triangles", "structured_mesh", "SIDES"]


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
