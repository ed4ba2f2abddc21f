"""Uniform red refinement: every triangle into four, every tetrahedron into eight (nested meshes).

Tetrahedra follow Bey (1995, "Tetrahedral grid refinement", Computing 55): four corner
children and an inner octahedron cut into four along one of its three diagonals. femkit cuts
along the *shortest* diagonal of each octahedron (the choice that keeps the children's shape
regular, Bey 1995 section 3; Zhang 1995), so the minimum dihedral angle stays bounded under
repeated refinement (docs/methods.md states the numbers after five levels). On a structured
Kuhn box (:func:`femkit.mesh.structured_box`) this gives the structured box of half the size.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(points=np.array([[0., 0.], [1., 0.], [0., 1.]]), triangles=np.array([[0, 1, 2]]))
>>> f = refine(m, levels=2)
>>> f.n_triangles, f.n_points, float(f.areas().sum())
(16, 15, 0.5)
"""

from __future__ import annotations

import numpy as np

from .bey_tables import CORNERS, DIAGONAL_PAIRS, DIAGONALS, FACE_PAIRS, INNER
from .edges import boundary_edge_ids, edge_ids, edges, remember_edges
from .quality import note_red_refinement
from .mesh import LOCAL_EDGES, Mesh
from ..warmup_registry import register_kernels, register_threshold

#: Triangle meshes with at least this many cells are refined by compiled passes
#: (:mod:`femkit.mesh._refine_kernel`; the same arrays as the NumPy path).
NUMBA_THRESHOLD = 50_000

#: Tetrahedral meshes with at least this many cells are refined by compiled passes
#: (:func:`~._refine_kernel.red_tetrahedra`: the same children as the NumPy path).
NUMBA_THRESHOLD_3D = 20_000
register_threshold(__name__, "NUMBA_THRESHOLD", "NUMBA_THRESHOLD_3D")
register_kernels("mesh passes", "femkit.mesh._refine_kernel", "red_children", "child_edges", "with_midpoints",
                 "interleaved_red", "interleaved_rows", rank=0)
register_kernels("mesh passes", "femkit.mesh._refine_kernel", "red_tetrahedra", "interleaved_bey", rank=0,
                 tetrahedra_only=True)


def refine_once(mesh: Mesh, *, derive_edges: bool = True) -> tuple[Mesh, np.ndarray]:
    """One level of red refinement, and the coarse edges whose midpoints are the new nodes.

    Returns ``(fine, edge_nodes)``: fine node ``n + e`` is the midpoint of coarse edge
    ``edge_nodes[e]`` (:func:`edges` order), so a nested prolongation needs no second edge search
    (:class:`femkit.mesh.hierarchy.MeshHierarchy`). On large triangle meshes the fine mesh's own
    edges are derived from the coarse ones on the way (:func:`~._refine_kernel.child_edges`) and
    given to :func:`edges`, so no level of a hierarchy searches its edges but the coarsest
    (``derive_edges=False``: not). A renumbered hierarchy refines large triangle meshes with
    :func:`refine_interleaved` instead, which derives them in its numbering.
    """
    if mesh.dim == 3:
        return _refine_tetrahedra(mesh)
    n = mesh.n_points
    edge_nodes, tri_edges = edges(mesh)
    t = mesh.triangles
    known = None
    if len(t) >= NUMBA_THRESHOLD:  # the same arrays from two compiled passes
        from ._refine_kernel import child_edges, red_children, with_midpoints

        points = with_midpoints(mesh.points, edge_nodes)
        children = red_children(t, tri_edges, n)
        if derive_edges:  # the fine mesh's, without a search
            known = child_edges(n, edge_nodes, t, tri_edges)
    else:
        points = np.vstack([mesh.points, mesh.points[edge_nodes].mean(axis=1)])
        m0, m1, m2 = (n + tri_edges[:, k] for k in range(3))
        v0, v1, v2 = t[:, 0], t[:, 1], t[:, 2]
        # children are counter-clockwise when the parent is; the four of a parent are contiguous
        children = np.stack([
            np.stack([v0, m2, m1], axis=1),
            np.stack([m2, v1, m0], axis=1),
            np.stack([m1, m0, v2], axis=1),
            np.stack([m0, m1, m2], axis=1),
        ], axis=1).reshape(-1, 3)
    fine = _fine_triangles(mesh, points, children, edge_nodes)
    note_red_refinement(fine, mesh)
    if known is not None:  # what edges(fine) would find: the next refinement, quality, estimator
        remember_edges(fine, *known)
    return fine, edge_nodes


def interleaves(mesh: Mesh) -> bool:
    """True when :func:`refine_interleaved` refines ``mesh`` (at least :data:`NUMBA_THRESHOLD`
    triangles or :data:`NUMBA_THRESHOLD_3D` tetrahedra); a hierarchy renumbers smaller ones
    after refining."""
    return mesh.n_cells >= (NUMBA_THRESHOLD if mesh.dim == 2 else NUMBA_THRESHOLD_3D)


def refine_interleaved(mesh: Mesh) -> tuple[Mesh, np.ndarray, np.ndarray]:
    """:func:`refine_once` numbered as :func:`femkit.mesh.hierarchy.interleave_permutation`
    orders the fine nodes (each coarse node followed by the midpoints of its edges to higher
    nodes), in one compiled pass (:func:`~._refine_kernel.interleaved_red`,
    :func:`~._refine_kernel.interleaved_bey`), the fine mesh's edges known in that numbering.

    Returns ``(fine, edge_nodes, inv)``: ``fine`` equals ``permute_nodes(refine_once(mesh)[0],
    perm, sort_elements=False)`` array for array, ``edge_nodes`` are the coarse edges as
    :func:`refine_once` returns them, and ``inv[j]`` is the new id of fine node ``j`` of
    :func:`refine_once`'s numbering (``perm``'s inverse).
    """
    from . import _refine_kernel as kernel
    from .edges import index_dtype

    edge_nodes, cell_edges = edges(mesh)
    k = 3 if mesh.dim == 2 else 6
    types = (np.zeros(0, index_dtype(mesh.n_points + len(edge_nodes))),
             np.zeros(0, index_dtype(2 ** mesh.dim * k * mesh.n_cells)))
    if mesh.dim == 2:
        points, children, inv, fine_edges, fine_cells = kernel.interleaved_red(
            mesh.points, mesh.cells, edge_nodes, cell_edges, LOCAL_EDGES[3], *types)
        fine = _fine_triangles(mesh, points, children, edge_nodes, inv)
        note_red_refinement(fine, mesh)
    else:
        points, children, inv, fine_edges, fine_cells = kernel.interleaved_bey(
            mesh.points, mesh.cells, edge_nodes, cell_edges, LOCAL_EDGES[4], *types, CORNERS,
            INNER, DIAGONALS, FACE_PAIRS, DIAGONAL_PAIRS)
        fine = _fine_tetrahedra(mesh, points, children, edge_nodes, inv)
    remember_edges(fine, fine_edges, fine_cells)
    return fine, edge_nodes, inv


def _fine_triangles(mesh: Mesh, points: np.ndarray, children: np.ndarray,
                    edge_nodes: np.ndarray, inv: np.ndarray | None = None) -> Mesh:
    """The refined triangle mesh: children inherit their parent's tag, each tagged boundary
    edge becomes its two halves (same direction); ``inv`` renumbers their nodes (the
    children are given renumbered)."""
    n = mesh.n_points
    be = mesh.boundary_edges
    if len(be):
        bm = n + boundary_edge_ids(mesh, edge_nodes)
        new_be = np.stack([np.stack([be[:, 0], bm], axis=1),
                           np.stack([bm, be[:, 1]], axis=1)], axis=1).reshape(-1, 2)
        new_bt = np.repeat(mesh.boundary_tags, 2)
        if inv is not None:
            new_be = inv[new_be]
    else:
        new_be, new_bt = be, mesh.boundary_tags
    return Mesh(points=points, triangles=children, cell_tags=np.repeat(mesh.cell_tags, 4),
                boundary_edges=new_be, boundary_tags=new_bt, tag_names=mesh.tag_names)


def _refine_tetrahedra(mesh: Mesh) -> tuple[Mesh, np.ndarray]:
    """Bey's red refinement of every tetrahedron (shortest inner diagonal), as :func:`refine_once`."""
    n = mesh.n_points
    edge_nodes, cell_edges = edges(mesh)
    if mesh.n_cells >= NUMBA_THRESHOLD_3D:  # the same arrays from two compiled passes
        from ._refine_kernel import red_tetrahedra, with_midpoints

        points = with_midpoints(mesh.points, edge_nodes)
        children = red_tetrahedra(points, mesh.cells, cell_edges, n, CORNERS, INNER, DIAGONALS)
    else:
        points = np.vstack([mesh.points, mesh.points[edge_nodes].mean(axis=1)])
        children = _tetrahedron_children(points, mesh.cells, cell_edges, n)
    return _fine_tetrahedra(mesh, points, children, edge_nodes), edge_nodes


def _tetrahedron_children(points: np.ndarray, cells: np.ndarray, cell_edges: np.ndarray,
                          n: int) -> np.ndarray:
    """The (8 m, 4) children of Bey's refinement by NumPy (small meshes; the compiled
    :func:`~._refine_kernel.red_tetrahedra` makes the same array on large ones)."""
    local = np.concatenate([cells, n + cell_edges], axis=1)              # (m, 10)
    d = points[local[:, DIAGONALS[:, 0]]] - points[local[:, DIAGONALS[:, 1]]]
    len2 = np.einsum("mkd,mkd->mk", d, d)
    # the shortest diagonal; ties (a Kuhn tetrahedron has two) go to the one closest to the
    # direction (1, 1, 1), so a structured Kuhn box refines into the structured box of half
    # the size (Bey's congruent children) whatever the vertex order
    tied = len2 <= len2.min(axis=1, keepdims=True) * (1.0 + 1e-10)
    align = np.abs(d.sum(axis=2)) / np.sqrt(len2)
    choice = np.argmax(np.where(tied, align, -1.0), axis=1)
    inner = INNER[choice]                                                 # (m, 4, 4)
    rows = np.arange(len(local))[:, None, None]
    children = np.concatenate([local[:, CORNERS], local[rows, inner]], axis=1)
    children = children.reshape(-1, 4)
    from .mesh import signed_volumes

    neg = signed_volumes(points, children) < 0
    children[neg, 2], children[neg, 3] = children[neg, 3], children[neg, 2].copy()
    return children


def _fine_tetrahedra(mesh: Mesh, points: np.ndarray, children: np.ndarray,
                     edge_nodes: np.ndarray, inv: np.ndarray | None = None) -> Mesh:
    """The refined tetrahedral mesh: ``children`` inherit their parent's tag, and each tagged
    boundary face becomes its four red children; ``inv`` renumbers their nodes (the children
    are given renumbered)."""
    n = mesh.n_points
    cell_tags = np.repeat(mesh.cell_tags, 8)

    bf = mesh.boundary_facets
    if len(bf):
        mab, mbc, mca = (n + edge_ids(mesh, edge_nodes, bf[:, [i, j]])
                         for i, j in ((0, 1), (1, 2), (2, 0)))
        a, b, c = bf[:, 0], bf[:, 1], bf[:, 2]
        new_bf = np.stack([np.stack([a, mab, mca], 1), np.stack([mab, b, mbc], 1),
                           np.stack([mca, mbc, c], 1), np.stack([mab, mbc, mca], 1)],
                          axis=1).reshape(-1, 3)
        new_bt = np.repeat(mesh.boundary_tags, 4)
        if inv is not None:
            new_bf = inv[new_bf]
    else:
        new_bf, new_bt = bf, mesh.boundary_tags
    return Mesh(points, children, cell_tags=cell_tags, boundary_facets=new_bf,
                boundary_tags=new_bt, tag_names=mesh.tag_names)


def refine(mesh: Mesh, levels: int = 1) -> Mesh:
    """Uniform red refinement: each triangle into four by its edge midpoints (each tetrahedron
    into eight, Bey 1995), ``levels`` times.

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
