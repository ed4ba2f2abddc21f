"""Edges of a triangle or tetrahedral mesh, and the boundary of a mesh (by tags, or topologically).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.]]), np.array([[0, 1, 2], [0, 2, 3]]))
>>> len(edges(m)[0]), boundary_nodes(m).tolist()
(5, [0, 1, 2, 3])
"""

from __future__ import annotations

import weakref
from typing import Iterable

import numpy as np

from ..errors import MeshError
from .mesh import LOCAL_EDGES, Mesh
from ..warmup_registry import register_kernels, register_threshold

__all__ = ["edges", "boundary_edges_topological", "boundary_nodes", "edge_ids", "boundary_edge_ids"]

#: Meshes with at least this many cells find their edges with the compiled counting-sort kernel
#: (:mod:`femkit.mesh._edges_kernel`); smaller ones with ``np.unique``.
NUMBA_THRESHOLD = 200_000
register_threshold(__name__, "NUMBA_THRESHOLD")
register_kernels("mesh passes", "femkit.mesh._edges_kernel", "cell_edges", "sort_buckets", rank=0)

#: ``edges(mesh)`` per mesh, computed once while the mesh lives: refinement, the prolongations,
#: the quality numbers and the estimators all ask for the same edges. The arrays are read-only.
_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _local_edges(cells: np.ndarray) -> np.ndarray:
    """(m, k, 2) local edges: triangles (v1, v2), (v2, v0), (v0, v1); tetrahedra
    :data:`LOCAL_EDGES`."""
    return cells[:, LOCAL_EDGES[cells.shape[1]]]


def edges(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Unique edges and the element -> edge map.

    Returns
    -------
    edge_nodes : (E, 2) int32 (int64 when the node ids do not fit)
        Node pairs, each sorted ascending, rows sorted lexicographically.
    cell_edges : (m, 3) or (m, 6) int32 (int64 when the edge ids do not fit)
        ``cell_edges[t, k]`` is the edge of triangle ``t`` opposite its local vertex ``k``, or
        the local edge ``k`` of a tetrahedron (:data:`LOCAL_EDGES`).

    Computed once per mesh (cached while the mesh lives; the arrays are read-only). 32-bit
    indices halve what the finest mesh's edges hold through a run (the estimator's, the
    quality numbers'); arithmetic on them (keys ``lo * n + hi``) is done in int64.
    """
    try:
        hit = _CACHE.get(mesh)
    except TypeError:  # a mesh-like object that cannot be weakly referenced
        return _edges(mesh)
    if hit is None:
        hit = _edges(mesh)
        for a in hit:
            a.flags.writeable = False
        _CACHE[mesh] = hit
    return hit


def known_edges(mesh: Mesh) -> tuple[np.ndarray, np.ndarray] | None:
    """The arrays :func:`edges` returns if they are known for ``mesh`` already (computed or
    remembered), else None: nothing is computed."""
    try:
        return _CACHE.get(mesh)
    except TypeError:
        return None


def remember_edges(mesh: Mesh, edge_nodes: np.ndarray, cell_edges: np.ndarray) -> None:
    """Give ``mesh`` the edges a caller derived without a search (red refinement derives the
    fine mesh's from the coarse mesh's): the arrays :func:`edges` would compute, which it then
    returns, with the same index types (:func:`index_dtype`)."""
    k = 3 if mesh.dim == 2 else 6
    edge_nodes = edge_nodes.astype(index_dtype(max(mesh.n_points, 1)), copy=False)
    cell_edges = cell_edges.astype(index_dtype(mesh.n_cells * k), copy=False)
    for a in (edge_nodes, cell_edges):
        a.flags.writeable = False
    try:
        _CACHE[mesh] = (edge_nodes, cell_edges)
    except TypeError:  # a mesh-like object that cannot be weakly referenced
        pass


def forget_edges(mesh: Mesh) -> None:
    """Drop ``mesh``'s cached edges (a coarser level of a hierarchy needs them only while it
    is refined; :func:`edges` computes them again if asked)."""
    try:
        _CACHE.pop(mesh, None)
    except TypeError:
        pass


def index_dtype(count: int) -> type:
    """int32 when ids ``0 .. count - 1`` fit in it, else int64."""
    return np.int32 if count <= np.iinfo(np.int32).max else np.int64


def _edges(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    n = max(mesh.n_points, 1)
    k = 3 if mesh.dim == 2 else 6
    node_type = index_dtype(n)
    edge_type = index_dtype(mesh.n_cells * k)  # at most one edge per local edge
    if NUMBA_THRESHOLD <= mesh.n_cells and mesh.n_cells * k < 2 ** 32:  # the kernel packs e k + j in 32 bits
        from ._edges_kernel import cell_edges

        return cell_edges(mesh.cells, LOCAL_EDGES[mesh.cells.shape[1]], n,
                          np.zeros(0, node_type), np.zeros(0, edge_type))
    loc = _local_edges(mesh.cells).reshape(-1, 2).astype(np.int64, copy=False)
    lo, hi = loc.min(axis=1), loc.max(axis=1)
    keys, inverse = np.unique(lo * n + hi, return_inverse=True)
    edge_nodes = np.stack([keys // n, keys % n], axis=1).astype(node_type)
    return edge_nodes, inverse.reshape(-1, k).astype(edge_type)


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
    """Sorted node ids on boundary facets (edges in 2D, faces in 3D) carrying any of ``tags``.

    ``tags=None`` finds the whole boundary topologically (facets of exactly one cell).
    Names and numbers are checked with :func:`femkit.mesh.validate.check_tags` (a missing tag
    raises :class:`~femkit.errors.MeshError` listing the available ones).
    """
    if tags is None:
        if mesh.dim == 3:
            from .faces import boundary_faces_topological

            return np.unique(boundary_faces_topological(mesh))
        return np.unique(boundary_edges_topological(mesh))
    from .validate import check_tags

    nums = check_tags(mesh, tags, kind="boundary")
    sel = np.isin(mesh.boundary_tags, nums)
    return np.unique(mesh.boundary_facets[sel])


def edge_ids(mesh: Mesh, edge_nodes: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Index in ``edge_nodes`` (from :func:`edges`) of each node pair in ``pairs`` (k, 2), any order.

    Raises :class:`~femkit.errors.MeshError` when a pair is not an edge of any triangle.
    """
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    n = max(mesh.n_points, 1)
    keys = edge_nodes[:, 0].astype(np.int64) * n + edge_nodes[:, 1]
    q = pairs.min(axis=1) * n + pairs.max(axis=1)
    pos = np.minimum(np.searchsorted(keys, q), max(len(keys) - 1, 0))
    bad = np.flatnonzero(keys[pos] != q) if len(keys) else np.arange(len(pairs))
    if len(bad):
        raise MeshError(f"{len(bad)} boundary edge(s) are not edges of any triangle "
                        f"(edge ids {', '.join(map(str, bad[:10]))})")
    return pos


def boundary_edge_ids(mesh: Mesh, edge_nodes: np.ndarray) -> np.ndarray:
    """Index in ``edge_nodes`` of each tagged boundary edge of ``mesh`` (see :func:`edge_ids`)."""
    return edge_ids(mesh, edge_nodes, mesh.boundary_edges)
