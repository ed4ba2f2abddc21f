"""Edges of a triangle mesh and its boundary (by tags, or topologically).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.]]), np.array([[0, 1, 2], [0, 2, 3]]))
>>> len(edges(m)[0]), boundary_nodes(m).tolist()
(5, [0, 1, 2, 3])
"""

from __future__ import annotations

from typing import Iterable

import numpy as np

from .mesh import Mesh

__all__ = ["edges", "boundary_edges_topological", "boundary_nodes"]


def _local_edges(tri: np.ndarray) -> np.ndarray:
    """(m, 3, 2) local edges; edge k is opposite vertex k: (v1, v2), (v2, v0), (v0, v1)."""
    return tri[:, [[1, 2], [2, 0], [0, 1]]]


def edges(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Unique edges and the element -> edge map.

    Returns
    -------
    edge_nodes : (E, 2) int64
        Node pairs, each sorted ascending, rows sorted lexicographically.
    tri_edges : (m, 3) int64
        ``tri_edges[t, k]`` is the edge of triangle ``t`` opposite its local vertex ``k``.
    """
    n = max(mesh.n_points, 1)
    loc = _local_edges(mesh.triangles).reshape(-1, 2)
    lo, hi = loc.min(axis=1), loc.max(axis=1)
    keys, inverse = np.unique(lo * n + hi, return_inverse=True)
    edge_nodes = np.stack([keys // n, keys % n], axis=1)
    return edge_nodes, inverse.reshape(-1, 3).astype(np.int64)


def boundary_edges_topological(mesh: Mesh) -> np.ndarray:
    """Edges used by exactly one triangle, oriented as in that triangle (domain on the left).

    Found from the connectivity alone, independent of any tags.
    """
    loc = _local_edges(mesh.triangles).reshape(-1, 2)
    _, tri_edges = edges(mesh)
    counts = np.bincount(tri_edges.ravel(), minlength=int(tri_edges.max(initial=-1)) + 1)
    once = counts[tri_edges.ravel()] == 1
    return loc[once]


def boundary_nodes(mesh: Mesh, tags: Iterable | str | int | None = None) -> np.ndarray:
    """Sorted node ids on boundary edges carrying any of ``tags``.

    ``tags=None`` finds the whole boundary topologically (edges of exactly one triangle).
    Names and numbers are checked with :func:`femkit.mesh.validate.check_tags` (a missing tag
    raises :class:`~femkit.errors.MeshError` listing the available ones).
    """
    if tags is None:
        return np.unique(boundary_edges_topological(mesh))
    from .validate import check_tags

    nums = check_tags(mesh, tags, kind="boundary")
    sel = np.isin(mesh.boundary_tags, nums)
    return np.unique(mesh.boundary_edges[sel])
