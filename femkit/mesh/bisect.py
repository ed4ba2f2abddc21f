"""Conforming local refinement by newest-vertex bisection, and the prolongation of nodal values.

Convention: the vertex order of each triangle carries its *refinement edge*: the edge opposite
local vertex 0 (the "newest vertex"), i.e. ``(v1, v2)``. Bisecting ``(v0, v1, v2)`` at the
midpoint ``m`` of ``(v1, v2)`` gives the children ``(m, v0, v1)`` and ``(m, v2, v0)``: both
counter-clockwise when the parent is, each with ``m`` as its newest vertex, so the children's
refinement edges are the parent's two other edges (Mitchell 1991; Binev, Dahmen & DeVore 2004).
Every triangle produced by repeated bisection is similar to one of at most four triangles per
initial triangle (Sewell 1972; Mitchell 1991), so the minimum angle stays bounded below by a
constant of the initial mesh, however many times one refines: :func:`min_angle_bound` computes it.

:func:`label_longest_edge` rotates each triangle so that its longest edge is its refinement edge
(a valid initial labelling: the closure terminates and refines no edge more than once per call).

The closure that keeps the mesh conforming is computed on edges, in rounds over the whole mesh
(never a loop over elements): an element with any marked edge gets its refinement edge marked,
until nothing changes. Each element is then split into 2, 3 or 4 children in one vectorised pass.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = label_longest_edge(Mesh(np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.]]),
...                             np.array([[0, 1, 2], [0, 2, 3]])))
>>> r = bisect(m, [0])          # refining one triangle bisects the shared diagonal in both
>>> r.mesh.n_triangles, r.mesh.n_points, float(r.mesh.areas().sum())
(4, 5, 1.0)
>>> r.prolong(np.array([0., 1., 2., 1.])).tolist()
[0.0, 1.0, 2.0, 1.0, 1.0]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .mesh import Mesh
from .quality import side_lengths_and_angles
from .edges import boundary_edge_ids, edges


@dataclass(frozen=True)
class Bisection:
    """The refined mesh and how it relates to the coarse one.

    Attributes
    ----------
    mesh : Mesh
        The refined mesh: the coarse nodes first (same order), then one new node per bisected
        coarse edge, in the order of ``new_node_edges``.
    parent : (m_fine,) int64
        Coarse element each fine element comes from (cell tags are inherited through it).
    new_node_edges : (k, 2) int (int32, as :func:`~femkit.mesh.edges.edges` gives them)
        The coarse edge (two coarse node ids) whose midpoint is each new node.
    """

    mesh: Mesh
    parent: np.ndarray
    new_node_edges: np.ndarray

    def prolong(self, u: np.ndarray) -> np.ndarray:
        """Interpolate coarse nodal values onto the fine mesh (exact for P1 functions).

        A new node, the midpoint of a coarse edge, gets the mean of the edge's two values.
        ``u`` may carry trailing dimensions (``(n,)`` or ``(n, d)``).
        """
        u = np.asarray(u, dtype=np.float64)
        n = len(self.mesh.points) - len(self.new_node_edges)
        if u.shape[:1] != (n,):
            raise InputError(f"prolong needs one value per coarse node ({n}), got shape {u.shape}")
        mid = 0.5 * (u[self.new_node_edges[:, 0]] + u[self.new_node_edges[:, 1]])
        return np.concatenate([u, mid])


def label_longest_edge(mesh: Mesh) -> Mesh:
    """Rotate each triangle's vertices so its longest edge is opposite local vertex 0.

    A cyclic rotation: orientation, node ids and tags are unchanged. Use it once on an initial
    mesh before the first :func:`bisect` (later meshes keep the labelling bisection gives them).
    """
    t = mesh.triangles
    p = mesh.points[t]                                    # (m, 3, 2)
    e = p[:, [2, 0, 1]] - p[:, [1, 2, 0]]                 # edge opposite vertex k
    k = np.argmax(np.einsum("mkd,mkd->mk", e, e), axis=1)
    rot = (k[:, None] + np.arange(3)[None, :]) % 3
    tri = np.take_along_axis(t, rot, axis=1)
    return Mesh(points=mesh.points, triangles=tri, cell_tags=mesh.cell_tags,
                boundary_edges=mesh.boundary_edges, boundary_tags=mesh.boundary_tags,
                tag_names=mesh.tag_names)


def min_angle_bound(mesh: Mesh, generations: int = 4) -> float:
    """The minimum angle (degrees) newest-vertex bisection can ever produce from ``mesh``.

    Every descendant of a labelled triangle is similar to one of its descendants of the first few
    generations (at most four similarity classes: Sewell 1972, Mitchell 1991), so the minimum over
    ``generations`` bisections of every triangle, each on its own, bounds all later meshes below.
    Vectorised over the triangles (``3 * 2^generations`` angles each).
    """
    p = mesh.points[mesh.triangles]                       # (m, 3, 2) labelled: v0 newest
    tris = [p]
    cur = p
    for _ in range(int(generations)):
        v0, v1, v2 = cur[:, 0], cur[:, 1], cur[:, 2]
        m = 0.5 * (v1 + v2)
        cur = np.concatenate([np.stack([m, v0, v1], axis=1), np.stack([m, v2, v0], axis=1)])
        tris.append(cur)
    _, angles = side_lengths_and_angles(np.concatenate(tris))
    return float(angles.min())


def _marked_elements(mesh: Mesh, marked) -> np.ndarray:
    """Element ids from a boolean mask or an id array (numpy's own indexing rules and checks)."""
    sel = np.asarray(marked)
    if sel.size == 0:
        return np.zeros(0, dtype=np.int64)
    if sel.dtype != bool and not np.issubdtype(sel.dtype, np.integer):
        raise InputError(f"marked must be element ids or a boolean mask, got dtype {sel.dtype}")
    try:
        return np.arange(mesh.n_triangles)[sel]
    except IndexError as exc:
        raise InputError(f"marked elements do not fit a mesh of {mesh.n_triangles} triangles: {exc}") from None


def closure(tri_edges: np.ndarray, edge_marked: np.ndarray) -> tuple[np.ndarray, int]:
    """Mark the refinement edge of every element that has a marked edge, until stable.

    Parameters
    ----------
    tri_edges : (m, 3) int
        Edge ids of each element, column k opposite local vertex k (column 0 = refinement edge).
    edge_marked : (E,) bool
        Edges to bisect (modified copy returned).

    Returns
    -------
    (edge_marked, rounds): the closed edge marks and the number of sweeps it took.
    """
    marked = edge_marked.copy()
    rounds = 0
    while True:
        need = marked[tri_edges].any(axis=1) & ~marked[tri_edges[:, 0]]
        if not need.any():
            return marked, rounds
        marked[tri_edges[need, 0]] = True
        rounds += 1


def bisect(mesh: Mesh, marked) -> Bisection:
    """Refine the marked elements by newest-vertex bisection, plus the closure that keeps it conforming.

    Parameters
    ----------
    mesh : Mesh
        Labelled triangles (refinement edge opposite local vertex 0; see :func:`label_longest_edge`).
    marked : (m,) bool mask or element ids
        Elements that must be refined (each is bisected at least once, its refinement edge at least).

    Returns
    -------
    Bisection
        Refined mesh (cell tags inherited; each bisected tagged boundary edge becomes two edges
        with its tag and direction), parent map and new-node edges for :meth:`Bisection.prolong`.

    Raises
    ------
    InputError
        Bad ``marked``. :class:`~femkit.errors.MeshError` when a tagged boundary edge is not an
        edge of the triangulation.
    """
    ids = _marked_elements(mesh, marked)
    n = mesh.n_points
    edge_nodes, te = edges(mesh)
    emark = np.zeros(len(edge_nodes), dtype=bool)
    emark[te[ids, 0]] = True
    emark, _ = closure(te, emark)

    new_edges = np.flatnonzero(emark)
    mid_id = np.full(len(edge_nodes), -1, dtype=np.int64)
    mid_id[new_edges] = n + np.arange(len(new_edges))
    points = np.vstack([mesh.points, mesh.points[edge_nodes[new_edges]].mean(axis=1)])

    t = mesh.triangles
    refined = emark[te[:, 0]]
    left = emark[te[:, 2]] & refined       # edge (v0, v1): the first child's refinement edge
    right = emark[te[:, 1]] & refined      # edge (v2, v0): the second child's refinement edge
    keep = np.flatnonzero(~refined)
    v0, v1, v2 = t[:, 0], t[:, 1], t[:, 2]
    mid = mid_id[te[:, 0]]
    pl, pr = mid_id[te[:, 2]], mid_id[te[:, 1]]

    blocks = [t[keep]]
    parents = [keep]
    # first child (m, v0, v1): kept whole, or split at the midpoint p of (v0, v1)
    a = np.flatnonzero(refined & ~left)
    blocks.append(np.stack([mid[a], v0[a], v1[a]], axis=1)); parents.append(a)
    a = np.flatnonzero(left)
    blocks.append(np.stack([pl[a], mid[a], v0[a]], axis=1)); parents.append(a)
    blocks.append(np.stack([pl[a], v1[a], mid[a]], axis=1)); parents.append(a)
    # second child (m, v2, v0): kept whole, or split at the midpoint q of (v2, v0)
    a = np.flatnonzero(refined & ~right)
    blocks.append(np.stack([mid[a], v2[a], v0[a]], axis=1)); parents.append(a)
    a = np.flatnonzero(right)
    blocks.append(np.stack([pr[a], mid[a], v2[a]], axis=1)); parents.append(a)
    blocks.append(np.stack([pr[a], v0[a], mid[a]], axis=1)); parents.append(a)
    tri = np.concatenate(blocks)
    parent = np.concatenate(parents).astype(np.int64)

    be, bt = _split_boundary_edges(mesh, edge_nodes, mid_id)
    fine = Mesh(points=points, triangles=tri, cell_tags=mesh.cell_tags[parent],
                boundary_edges=be, boundary_tags=bt, tag_names=mesh.tag_names)
    return Bisection(mesh=fine, parent=parent, new_node_edges=edge_nodes[new_edges])


def _split_boundary_edges(mesh: Mesh, edge_nodes: np.ndarray, mid_id: np.ndarray):
    be, bt = mesh.boundary_edges, mesh.boundary_tags
    if not len(be):
        return be, bt
    pos = boundary_edge_ids(mesh, edge_nodes)
    mid = mid_id[pos]
    split = mid >= 0
    halves = np.stack([np.stack([be[split, 0], mid[split]], axis=1),
                       np.stack([mid[split], be[split, 1]], axis=1)], axis=1).reshape(-1, 2)
    return (np.concatenate([be[~split], halves]),
            np.concatenate([bt[~split], np.repeat(bt[split], 2)]))
