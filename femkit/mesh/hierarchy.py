"""Nested meshes from uniform red refinement and their P1 prolongations (geometric multigrid).

Red refinement nests the P1 spaces ``V_0 ⊂ V_1 ⊂ ... ⊂ V_L``: a coarse node is a fine node, and
a new node, the midpoint of a coarse edge, takes the mean of the edge's end values. That is the
prolongation ``P_l: V_l -> V_{l+1}``, exact on every coarse P1 function (Briggs, Henson and McCormick,
*A Multigrid Tutorial*, 2nd ed., SIAM 2000, ch. 10; Trottenberg, Oosterlee and Schüller,
*Multigrid*, 2001): the identity on the coarse nodes and two weights ``1/2`` per midpoint, built
once per level from the edge list the refinement produced (no search).

Dirichlet elimination keeps the free nodes only (:func:`femkit.fem.apply_dirichlet`); a fixed
fine node carries a zero correction, so the free-dof prolongation is ``P_l[free_{l+1}][:, free_l]``
(:meth:`MeshHierarchy.free_prolongations`), and a coarse node is free when the fine node it
becomes is free (:meth:`MeshHierarchy.level_free`).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(points=np.array([[0., 0.], [1., 0.], [0., 1.]]), triangles=np.array([[0, 1, 2]]))
>>> H = MeshHierarchy.from_refinement(m, 2)
>>> H.n_levels, [mesh.n_points for mesh in H.meshes], H.prolongations[0].shape
(3, [3, 6, 15], (6, 3))
>>> u = H.coarsest.points @ [2.0, -1.0] + 0.5          # a linear function: reproduced exactly
>>> bool(np.allclose(H.prolongate(u, 0), H.meshes[1].points @ [2.0, -1.0] + 0.5))
True
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from .edges import forget_edges
from .mesh import Mesh
from .refine import interleaves, refine_interleaved, refine_once


def prolongation(n_coarse: int, edge_nodes: np.ndarray) -> sp.csr_matrix:
    """P1 prolongation of one red refinement: ``(n_coarse + E, n_coarse)`` CSR.

    Row ``i < n_coarse`` is the unit vector ``e_i``; row ``n_coarse + e`` has ``1/2`` at both
    nodes of ``edge_nodes[e]`` (the nesting of :func:`femkit.mesh.refine`). Indices are int32
    while the entries fit (SciPy's own choice; half the memory of int64: 4 bytes per entry and
    per row less, 21 MB at 1.9M fine nodes), int64 beyond.
    """
    n_edges = len(edge_nodes)
    nnz = n_coarse + 2 * n_edges
    idx = np.int32 if max(nnz, n_coarse + n_edges) <= np.iinfo(np.int32).max else np.int64
    indptr = np.concatenate([np.arange(n_coarse + 1, dtype=idx),
                             n_coarse + 2 * np.arange(1, n_edges + 1, dtype=idx)])
    indices = np.concatenate([np.arange(n_coarse, dtype=idx),
                              np.asarray(edge_nodes).astype(idx, copy=False).ravel()])
    data = np.concatenate([np.ones(n_coarse), np.full(2 * n_edges, 0.5)])
    return sp.csr_matrix((data, indices, indptr), shape=(n_coarse + n_edges, n_coarse))


def interleaved_prolongation(n_coarse: int, edge_nodes: np.ndarray, inv: np.ndarray) -> sp.csr_matrix:
    """:func:`prolongation` with its rows renumbered: row ``inv[j]`` is row ``j`` (the same
    matrix as ``prolongation(n_coarse, edge_nodes)[perm]``, ``perm`` the inverse of ``inv``),
    built directly by one compiled pass (:func:`~._refine_kernel.interleaved_rows`): a coarse
    node's row holds one entry, a midpoint's two, in 32-bit indices when they fit (as SciPy
    would store them)."""
    from ._refine_kernel import interleaved_rows

    n_fine = n_coarse + len(edge_nodes)
    idx = np.int32 if n_fine + len(edge_nodes) < np.iinfo(np.int32).max else np.int64
    indptr, indices, data = interleaved_rows(n_coarse, edge_nodes, inv, np.zeros(0, idx))
    return sp.csr_matrix((data, indices, indptr), shape=(n_fine, n_coarse))


def _restrict_free(P: sp.csr_matrix, rows: np.ndarray, cols: np.ndarray) -> sp.csr_matrix:
    """``P[rows][:, cols]`` for increasing ``rows`` (without repeats), by array operations.

    A column map (old column -> new, -1 for a dropped column) renumbers every entry; the entries
    of the dropped rows are marked dropped too. Only the dropped entries (those of the Dirichlet
    nodes: few) are then located, to correct the row counts, and one mask compresses ``data``
    and ``indices``: O(nnz + n_rows + n_cols) vectorised numpy, entries in their order, the same
    arrays as SciPy's ``P[rows][:, cols]`` (which builds an intermediate matrix and takes about
    1.5x as long on a prolongation).

    >>> P = sp.csr_matrix(np.array([[1.0, 0, 0], [0.5, 0.5, 0], [0, 0.5, 0.5], [0, 0, 1]]))
    >>> _restrict_free(P, np.array([1, 2]), np.array([0, 2])).toarray()
    array([[0.5, 0. ],
           [0. , 0.5]])
    """
    n_rows, n_cols = P.shape
    idx = P.indices.dtype
    col_map = np.full(n_cols, -1, dtype=idx)
    col_map[cols] = np.arange(len(cols), dtype=idx)
    new_cols = col_map[P.indices]
    row_kept = np.zeros(n_rows, dtype=bool)
    row_kept[rows] = True
    gone = np.flatnonzero(~row_kept)
    starts = P.indptr[gone]
    lens = P.indptr[gone + 1] - starts
    new_cols[np.repeat(starts - (np.cumsum(lens) - lens), lens) + np.arange(lens.sum())] = -1
    dropped = np.flatnonzero(new_cols < 0)
    counts = np.diff(P.indptr)
    counts -= np.bincount(np.searchsorted(P.indptr, dropped, side="right") - 1,
                          minlength=n_rows).astype(counts.dtype, copy=False)
    indptr = np.zeros(len(rows) + 1, dtype=idx)
    np.cumsum(counts[row_kept], out=indptr[1:])
    keep = np.ones(P.nnz, dtype=bool)
    keep[dropped] = False
    return sp.csr_matrix((P.data[keep], new_cols[keep], indptr), shape=(len(rows), len(cols)))


def _fixed_columns(P: sp.csr_matrix, rows: np.ndarray, col_fixed: np.ndarray) -> sp.csr_matrix:
    """``P[rows][:, cols]`` for increasing ``rows`` and the columns where ``col_fixed`` (a
    boolean mask), entries in their order: the few entries of ``P`` that carry the Dirichlet
    values of the coarse level to the free fine nodes (midpoints of edges with a fixed end).
    Only those entries are located (one boolean pass over the column indices), so the
    temporaries are a byte per entry of ``P``.

    >>> P = sp.csr_matrix(np.array([[1.0, 0, 0], [0.5, 0.5, 0], [0, 0.5, 0.5], [0, 0, 1]]))
    >>> _fixed_columns(P, np.array([1, 2]), np.array([True, False, True])).toarray()
    array([[0.5, 0. ],
           [0. , 0.5]])
    """
    idx = P.indices.dtype
    ent = np.flatnonzero(col_fixed[P.indices])
    row = np.searchsorted(P.indptr, ent, side="right") - 1
    pos = np.searchsorted(rows, row)
    hit = pos < len(rows)
    hit[hit] = rows[pos[hit]] == row[hit]    # the entry's row is one of ``rows``
    ent, pos = ent[hit], pos[hit]
    col_map = np.cumsum(col_fixed, dtype=np.int64) - 1
    indptr = np.zeros(len(rows) + 1, dtype=np.int64)
    np.cumsum(np.bincount(pos, minlength=len(rows)), out=indptr[1:])
    return sp.csr_matrix((P.data[ent], col_map[P.indices[ent]].astype(idx), indptr.astype(idx)),
                         shape=(len(rows), int(col_fixed.sum())))


def _free_mask(n: int, free) -> np.ndarray:
    """A new boolean mask of ``n`` nodes from free node ids or a mask of them.

    Raises
    ------
    InputError
        ``free`` is not a mask of ``n`` nodes nor valid node ids.
    """
    arr = np.asarray(free)
    if arr.dtype == bool:
        if arr.shape != (n,):
            raise InputError(f"a free-node mask must have shape ({n},) (the finest mesh's "
                             f"nodes), got {arr.shape}")
        return arr.copy()
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        raise InputError(f"free must be node ids (integers) or a boolean mask, got {arr.dtype}")
    arr = arr.astype(np.int64).ravel()
    if arr.size and (arr.min() < 0 or arr.max() >= n):
        raise InputError(f"free node ids out of range 0..{n - 1} (the finest mesh's nodes)")
    mask = np.zeros(n, dtype=bool)
    mask[arr] = True
    return mask


def interleave_permutation(n_coarse: int, edge_nodes: np.ndarray) -> np.ndarray:
    """Fine-level order keeping a locality-ordered coarse level local: every coarse node is
    followed by the midpoints of its edges to higher-numbered nodes (``perm[j]`` = old id of new
    node ``j``; old ids as :func:`femkit.mesh.refine` numbers them). A stable merge of two sorted
    sequences, O(n); the children of a coarse triangle stay contiguous, so elements need no sort.
    """
    lo = np.asarray(edge_nodes[:, 0], dtype=np.int64)
    # the merge needs no sort: coarse node v goes after v nodes and the edges of lower nodes
    # (edges are sorted by their lower node), edge e after its lower node and the e edges before
    below = np.zeros(n_coarse + 1, dtype=np.int64)
    np.cumsum(np.bincount(lo, minlength=n_coarse), out=below[1:])
    inv = np.concatenate([np.arange(n_coarse, dtype=np.int64) + below[:-1],
                          lo + 1 + np.arange(len(lo), dtype=np.int64)])
    perm = np.empty_like(inv)
    perm[inv] = np.arange(len(inv), dtype=np.int64)
    return perm


class _Levels:
    """What both hierarchies answer from their ``meshes`` (coarsest first)."""

    meshes: tuple

    @property
    def n_levels(self) -> int:
        """Number of meshes (refinements + 1)."""
        return len(self.meshes)

    @property
    def finest(self) -> Mesh:
        return self.meshes[-1]

    @property
    def coarsest(self) -> Mesh:
        return self.meshes[0]


@dataclass(frozen=True, eq=False)
class QuadraticNodes:
    """The nodes of P2 on ``mesh`` (its vertices, then one per edge), as the finest level of a
    :class:`MeshHierarchy` (:meth:`MeshHierarchy.with_quadratic_level`): what multigrid reads
    of a level, its node count ``n_points``, and ``dim``."""

    mesh: Mesh
    n_points: int

    @property
    def dim(self) -> int:
        return self.mesh.dim


@dataclass(frozen=True, eq=False)
class MeshHierarchy(_Levels):
    """Nested meshes, coarsest first, and the prolongations between consecutive levels.

    Attributes
    ----------
    meshes : tuple of Mesh
        ``meshes[0]`` the coarsest, ``meshes[-1]`` the finest (the mesh a case solves on).
    prolongations : tuple of csr_matrix
        ``prolongations[l]`` maps nodal values on level ``l`` to level ``l + 1``,
        shape ``(n_{l+1}, n_l)``; built once.
    injections : tuple of ndarray
        ``injections[l][i]`` is the node of level ``l + 1`` that coarse node ``i`` becomes
        (``arange(n_l)`` without renumbering: the coarse nodes come first).
    renumbering : str
        ``"none"`` or ``"rcm"`` (the coarsest level renumbered by reverse Cuthill-McKee,
        :mod:`femkit.mesh.renumber`, every finer level by :func:`interleave_permutation`;
        prolongations and injections follow).

    """

    meshes: tuple
    prolongations: tuple
    injections: tuple
    renumbering: str = "none"

    @classmethod
    def from_refinement(cls, coarse: Mesh, levels: int, *, renumber: str = "none") -> "MeshHierarchy":
        """Refine ``coarse`` uniformly ``levels`` times, keeping every level.

        Parameters
        ----------
        coarse : Mesh
            Level 0 (generated or read).
        levels : int
            Number of refinements (``>= 0``); the hierarchy has ``levels + 1`` meshes and its
            finest mesh equals ``refine(coarse, levels)`` (node for node when ``renumber="none"``).
        renumber : {"none", "rcm"}
            Number every level for memory locality: reverse Cuthill-McKee on the coarse mesh
            (:func:`femkit.mesh.renumber.renumber`), then each refinement's midpoints right after
            their edge's lower node (:func:`interleave_permutation`; RCM on every fine level costs
            more than it saves). ``"none"``: refinement's own numbering, coarse nodes first.
            Gauss-Seidel smooths in storage order, so the numbering changes the V-cycle slightly
            (V(2,2) factor at 7 levels, L-shape: 0.133 with ``"none"``, 0.147 with ``"rcm"``),
            while ``"rcm"`` makes a cycle 2.6x faster at 3.7M elements (docs/benchmarks.md).

        Raises
        ------
        InputError
            ``levels`` not a non-negative integer.
        """
        from .renumber import permute_nodes, renumber as _renumber

        if isinstance(levels, bool) or int(levels) != levels or levels < 0:
            raise InputError(f"levels must be a non-negative integer, got {levels!r}")
        mesh, _ = _renumber(coarse, renumber)
        meshes, prols, injs = [mesh], [], []
        for _ in range(int(levels)):
            n_c = mesh.n_points
            if renumber != "none" and interleaves(mesh):
                # refined straight into the interleaved numbering (one compiled pass, the fine
                # edges derived in it), P's rows built in it
                fine, edge_nodes, inv = refine_interleaved(mesh)
                # the injection is a copy: a view would keep all of ``inv`` (n_fine int64, 15 MiB
                # at 1.9M fine nodes) alive with the hierarchy for a quarter of it
                P, inj = interleaved_prolongation(n_c, edge_nodes, inv), inv[:n_c].copy()
            else:
                fine, edge_nodes = refine_once(mesh)
                P, inj = prolongation(n_c, edge_nodes), np.arange(n_c, dtype=np.int64)
                if renumber != "none":
                    perm = interleave_permutation(n_c, edge_nodes)
                    fine = permute_nodes(fine, perm, sort_elements=False)
                    inv = np.empty_like(perm)
                    inv[perm] = np.arange(len(perm))
                    P, inj = P[perm], inv[:n_c].copy()
            forget_edges(mesh)  # kept only through edge_nodes, which P needs
            meshes.append(fine)
            prols.append(P.tocsr())
            injs.append(inj)
            mesh = fine
        return cls(tuple(meshes), tuple(prols), tuple(injs), renumber)

    def prolongate(self, u: np.ndarray, level: int) -> np.ndarray:
        """Interpolate full nodal values ``u`` on ``level`` to ``level + 1`` (``P_level @ u``)."""
        return self.prolongations[level] @ np.asarray(u, dtype=np.float64)

    def level_free(self, free) -> list[np.ndarray]:
        """Free node ids of every level (coarsest first) from the finest level's free set.

        ``free``: sorted node ids of the finest mesh (``DirichletSystem.free``) or a boolean mask
        of its nodes. A coarse node is free when the fine node it becomes is free.

        Raises
        ------
        InputError
            ``free`` is not a mask of the finest mesh's nodes nor valid node ids.
        """
        mask = _free_mask(self.finest.n_points, free)
        ids = np.asarray(free)
        # increasing int64 ids (DirichletSystem.free) are the finest level's list as they are:
        # no second copy of n node ids
        same = (ids.dtype == np.int64 and ids.ndim == 1 and len(ids) == np.count_nonzero(mask)
                and bool(np.all(ids[1:] > ids[:-1])))
        out = [ids if same else np.flatnonzero(mask)]
        for inj in reversed(self.injections):
            mask = mask[inj]
            out.append(np.flatnonzero(mask))
        return out[::-1]

    def free_prolongations(self, free) -> list[sp.csr_matrix]:
        """``P_l[free_{l+1}][:, free_l]`` for every level (Dirichlet nodes eliminated).

        ``free``: as for :meth:`level_free`. Built from ``P_l``'s arrays (a column map, the rows
        of the free fine nodes): the same matrices as SciPy's fancy indexing, in 2/3 of its time.
        """
        frees = self.level_free(free)
        return [_restrict_free(P.tocsr(), frees[lvl + 1], frees[lvl])
                for lvl, P in enumerate(self.prolongations)]

    def fixed_prolongations(self, free=None, *, frees=None) -> list[tuple[sp.csr_matrix, np.ndarray]]:
        """``(P_l[free_{l+1}][:, fixed_l], fixed_l)`` for every level: the part of each
        prolongation that carries level ``l``'s Dirichlet values (at its fixed nodes ``fixed_l``,
        sorted) to the free nodes of level ``l + 1``.

        With :meth:`free_prolongations` it splits the prolongation of a full nodal vector
        ``u = (x on free_l, g on fixed_l)``: ``(P_l u)[free_{l+1}] = Pf_l x + Pd_l g``, the
        same sums (a P1 row has at most two entries) without the full matrices or vectors.
        ``free``: as for :meth:`level_free`; or ``frees``, its output (the free ids of every
        level) when already known.

        >>> from femkit.mesh import Mesh, boundary_nodes
        >>> sq = Mesh(points=[[0, 0], [1, 0], [1, 1], [0, 1]], triangles=[[0, 1, 2], [0, 2, 3]])
        >>> H = MeshHierarchy.from_refinement(sq, 2)
        >>> free = np.setdiff1d(np.arange(H.finest.n_points), boundary_nodes(H.finest))
        >>> (Pd, fixed), f0, f1 = H.fixed_prolongations(free)[1], *H.level_free(free)[1:]
        >>> u = np.arange(H.meshes[1].n_points, dtype=float)   # free and fixed values
        >>> Pf = H.free_prolongations(free)[1]
        >>> bool(np.array_equal(Pf @ u[f0] + Pd @ u[fixed], H.prolongate(u, 1)[f1]))
        True
        """
        if frees is None:
            frees = self.level_free(free)
        out = []
        for lvl, P in enumerate(self.prolongations):
            fixed = np.ones(P.shape[1], dtype=bool)
            fixed[frees[lvl]] = False
            out.append((_fixed_columns(P.tocsr(), frees[lvl + 1], fixed), np.flatnonzero(fixed)))
        return out

    def with_quadratic_level(self) -> "MeshHierarchy":
        """This hierarchy with one more, finest level: the P2 nodes of its finest mesh (the
        p-level of P2 multigrid). Its "mesh" is :class:`QuadraticNodes` (the vertices, then one
        node per edge: the numbering of :func:`femkit.fem.dofs.dof_map`), its prolongation the
        interpolation of a P1 field into P2 (vertex values kept, an edge node the mean of its
        ends): the matrix of one red refinement (:func:`prolongation`), since the P2 nodes of a
        mesh are the vertices of its refinement. The Galerkin product of a P2 stiffness matrix
        with it is the P1 stiffness matrix of the same mesh (P1 is a subspace of P2).

        >>> sq = Mesh(points=[[0, 0], [1, 0], [1, 1], [0, 1]], triangles=[[0, 1, 2], [0, 2, 3]])
        >>> H = MeshHierarchy.from_refinement(sq, 1).with_quadratic_level()
        >>> H.n_levels, H.finest.n_points, H.prolongations[-1].shape
        (3, 25, (25, 9))
        """
        from dataclasses import replace

        from .edges import edges

        fine = self.finest
        edge_nodes, _ = edges(fine)
        n = fine.n_points
        top = QuadraticNodes(fine, n + len(edge_nodes))
        return replace(self, meshes=self.meshes + (top,),
                       prolongations=self.prolongations + (prolongation(n, edge_nodes),),
                       injections=self.injections + (np.arange(n, dtype=np.int64),))

    def without_coarse_meshes(self) -> "MeshHierarchy":
        """The same levels and transfers with the coarser meshes dropped (``None``; the finest
        kept): all a multigrid solve reads once the coarser levels' loads are assembled (sizes,
        injections, prolongations), so their cells and points can be released during the solve
        (a third of the finest mesh's arrays in 2D, a seventh in 3D)."""
        from dataclasses import replace

        return replace(self, meshes=(None,) * (self.n_levels - 1) + (self.finest,))

    def on_free_nodes(self, free, *, fixed_parts: bool = True) -> "FreeNodeHierarchy":
        """The transfers of one set of free nodes, without the full prolongations: what a
        multigrid solve on ``free`` reads (:meth:`free_prolongations`, with ``fixed_parts``
        also :meth:`fixed_prolongations`, the injections, the meshes held here), built once.

        Held instead of this hierarchy during a solve, it lets the full matrices go: at 1.9M
        fine nodes they are 61 MiB beside the 61 MiB of the restricted ones. ``free``: as for
        :meth:`level_free`.

        >>> from femkit.mesh import Mesh, boundary_nodes
        >>> sq = Mesh(points=[[0, 0], [1, 0], [1, 1], [0, 1]], triangles=[[0, 1, 2], [0, 2, 3]])
        >>> H = MeshHierarchy.from_refinement(sq, 2)
        >>> free = np.setdiff1d(np.arange(H.finest.n_points), boundary_nodes(H.finest))
        >>> F = H.on_free_nodes(free)
        >>> all((a != b).nnz == 0 for a, b in zip(F.free_prolongations(free),
        ...                                       H.free_prolongations(free)))
        True
        """
        frees = self.level_free(free)
        prols = tuple(_restrict_free(P.tocsr(), frees[lvl + 1], frees[lvl])
                      for lvl, P in enumerate(self.prolongations))
        # the fixed parts as CSC: a few entries, while a CSR indptr has a slot per free fine node
        # (10 MiB at 1.9M); a P1 row has at most two entries, which CSC's product adds in
        # CSR's order (increasing column) from zero: the same sums
        fixed = (tuple((Pd.tocsc(), fx) for Pd, fx in self.fixed_prolongations(frees=frees))
                 if fixed_parts else None)
        return FreeNodeHierarchy(self.meshes, self.injections, tuple(frees), prols, fixed,
                                 self.renumbering)

    def __repr__(self) -> str:
        sizes = ", ".join(str(P.shape[1]) for P in self.prolongations)
        sizes = ", ".join(filter(None, (sizes, str(self.finest.n_points))))
        return f"MeshHierarchy(levels={self.n_levels}, nodes=[{sizes}], renumbering={self.renumbering!r})"


@dataclass(frozen=True, eq=False)
class FreeNodeHierarchy(_Levels):
    """A :class:`MeshHierarchy`'s transfers restricted to one set of free nodes
    (:meth:`MeshHierarchy.on_free_nodes`): the matrices a multigrid solve on those nodes reads,
    without the full prolongations. It answers :meth:`level_free`, :meth:`free_prolongations`
    and :meth:`fixed_prolongations` for that set only (anything else is refused).

    Attributes
    ----------
    meshes, injections, renumbering
        As :class:`MeshHierarchy` holds them.
    frees : tuple of ndarray
        Free node ids of every level (coarsest first).
    free_parts : tuple of csr_matrix
        ``P_l[free_{l+1}][:, free_l]`` (:meth:`MeshHierarchy.free_prolongations`).
    fixed_parts : tuple or None
        ``(P_l[free_{l+1}][:, fixed_l], fixed_l)`` (:meth:`MeshHierarchy.fixed_prolongations`;
        the matrices as CSC), None when not built.
    """

    meshes: tuple
    injections: tuple
    frees: tuple
    free_parts: tuple
    fixed_parts: tuple | None
    renumbering: str = "none"

    def level_free(self, free) -> list[np.ndarray]:
        """The free node ids of every level (coarsest first), as :meth:`MeshHierarchy.level_free`.

        Raises
        ------
        InputError
            ``free`` is not the set the transfers were restricted to.
        """
        self._check(free)
        return list(self.frees)

    def free_prolongations(self, free) -> list[sp.csr_matrix]:
        """The restricted prolongations (:meth:`MeshHierarchy.free_prolongations`), not copies."""
        self._check(free)
        return list(self.free_parts)

    def fixed_prolongations(self, free=None, *, frees=None) -> list[tuple[sp.csr_matrix, np.ndarray]]:
        """The fixed-column parts (:meth:`MeshHierarchy.fixed_prolongations`), not copies.

        Raises
        ------
        InputError
            Another free set, or the parts were not built (``fixed_parts=False``).
        """
        self._check(frees[-1] if frees is not None else free)
        if self.fixed_parts is None:
            raise InputError("this hierarchy was restricted to its free nodes without the "
                             "fixed-column parts of its prolongations (fixed_parts=False)")
        return list(self.fixed_parts)

    def _check(self, free) -> None:
        mine = self.frees[-1]
        if free is mine:    # the ids handed out here (Multigrid passes them back): no O(n) check
            return
        if not np.array_equal(np.flatnonzero(_free_mask(self.finest.n_points, free)), mine):
            raise InputError("the hierarchy's transfers were restricted to other free nodes "
                             "(MeshHierarchy.on_free_nodes); restrict the full hierarchy to these")

    def __repr__(self) -> str:
        sizes = ", ".join(str(len(f)) for f in self.frees)
        return (f"FreeNodeHierarchy(levels={self.n_levels}, free nodes=[{sizes}], "
                f"renumbering={self.renumbering!r})")
