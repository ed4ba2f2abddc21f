"""Partitioning the nodes of a mesh over MPI ranks and renumbering them contiguously.

The partitioner is PETSc's ``MatPartitioning`` with PT-Scotch (``ptscotch``; Debian's PETSc
has no ParMETIS, whose licence is not free): it is parallel (each rank hands in the rows of
the node adjacency graph of its naive block), it comes with the PETSc install femkit already
needs, and it minimises the edge cut, i.e. the off-rank couplings of the matrix. Any other
``MatPartitioning`` type can be chosen (``method=``; ``average``/``square`` are the trivial
ones). Nodes are then renumbered so each rank owns one contiguous block (PETSc's MPIAIJ row
distribution), keeping the original order inside a block; each element goes to the rank that
owns most of its vertices (the middle of its three owners). With P2 the unknowns are the dofs of
the dof map (:func:`femkit.fem.dofs.dof_map`: the nodes, then one per edge), renumbered the same
way; an edge's dof belongs to the owner of its lower-numbered node (:func:`dof_owners`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...solvers.petsc.env import require_petsc

#: MatPartitioning type used by default
DEFAULT_PARTITIONER = "ptscotch"


def naive_ranges(n: int, size: int) -> np.ndarray:
    """Offsets ``(size + 1,)`` of an even split of ``n`` items (PETSc's PETSC_DECIDE split)."""
    counts = np.full(size, n // size, dtype=np.int64)
    counts[: n % size] += 1
    return np.concatenate([[0], np.cumsum(counts)])


def adjacency_rows(cells: np.ndarray, start: int, end: int):
    """CSR ``(indptr, indices)`` of the node graph (mesh edges, no diagonal) for rows
    ``start <= i < end``, column indices sorted; ``cells`` are triangles or tetrahedra."""
    import scipy.sparse as sp

    mine = (cells >= start) & (cells < end)
    tri = cells[mine.any(axis=1)]
    k = cells.shape[1]
    i = np.repeat(tri, k, axis=1).ravel()  # every ordered vertex pair of each cell
    j = np.tile(tri, (1, k)).ravel()
    keep = (i >= start) & (i < end) & (i != j)
    n = int(cells.max()) + 1 if cells.size else 0
    G = sp.csr_matrix((np.ones(int(keep.sum()), dtype=np.int8), (i[keep] - start, j[keep])),
                      shape=(end - start, n))  # duplicates summed: one entry per edge
    G.sort_indices()
    return G.indptr.astype(np.int64), G.indices.astype(np.int64)


def partition_nodes(mesh, comm, *, method: str = DEFAULT_PARTITIONER) -> np.ndarray:
    """Owner rank of every node (the same ``(n,)`` array on every rank of the PETSc ``comm``)."""
    PETSc = require_petsc()
    size = comm.getSize()
    n = mesh.n_points
    if size == 1:
        return np.zeros(n, dtype=np.int64)
    if n < size:
        raise InputError(f"{n} nodes cannot be shared by {size} ranks")
    off = naive_ranges(n, size)
    r = comm.getRank()
    indptr, cols = adjacency_rows(mesh.cells, int(off[r]), int(off[r + 1]))
    nloc = int(off[r + 1] - off[r])
    adj = PETSc.Mat().createAIJ(size=((nloc, n), (nloc, n)),
                                csr=(indptr.astype(PETSc.IntType), cols.astype(PETSc.IntType),
                                     np.ones(len(cols))), comm=comm)
    part = PETSc.MatPartitioning().create(comm)
    try:
        part.setAdjacency(adj)
        try:
            part.setType(method)
        except PETSc.Error:
            raise InputError(f"PETSc MatPartitioning type {method!r} is not available in this "
                             f"PETSc build") from None
        part.setFromOptions()
        isp = PETSc.IS()
        part.apply(isp)
        local = np.asarray(isp.getIndices(), dtype=np.int64).copy()
        isp.destroy()
    finally:
        part.destroy()
        adj.destroy()
    owner = np.concatenate(comm.tompi4py().allgather(local))
    if np.bincount(owner, minlength=size).min() == 0:  # a degenerate partition: fall back
        owner = np.repeat(np.arange(size), np.diff(off))
    return owner


@dataclass
class Layout:
    """Node and unknown (dof) numbering of a partitioned mesh on one rank. With P2 a "node"
    here is a dof of the dof map (the mesh's nodes, then its edges: :func:`dof_owners`).

    Attributes
    ----------
    rank, size : int
    owner : (n,) int
        Owner rank of each (original) node.
    node_id : (n,) int
        New global node index of each original node (each rank's nodes contiguous).
    node_offsets : (size + 1,) int
        Rank ``r`` owns new node indices ``node_offsets[r] <= i < node_offsets[r + 1]``.
    owned : (n_local,) int
        Original ids of this rank's nodes, in new order.
    dof : (n,) int
        Global unknown index of each original node, ``-1`` for eliminated (Dirichlet) nodes.
    dof_offsets : (size + 1,) int
        Rank ``r`` owns unknowns ``dof_offsets[r] <= d < dof_offsets[r + 1]``.
    elements : (k,) int
        This rank's elements (the ones it assembles).
    """

    rank: int
    size: int
    owner: np.ndarray
    node_id: np.ndarray
    node_offsets: np.ndarray
    owned: np.ndarray
    dof: np.ndarray
    dof_offsets: np.ndarray
    elements: np.ndarray

    @property
    def n_local_nodes(self) -> int:
        return int(self.node_offsets[self.rank + 1] - self.node_offsets[self.rank])

    @property
    def n_local_dofs(self) -> int:
        return int(self.dof_offsets[self.rank + 1] - self.dof_offsets[self.rank])

    @property
    def owned_free(self) -> np.ndarray:
        """Mask over :attr:`owned`: which of this rank's nodes are unknowns."""
        return self.dof[self.owned] >= 0


def element_owners(cells: np.ndarray, owner: np.ndarray) -> np.ndarray:
    """Rank of each element: the second smallest of its vertices' owners (on a triangle the
    middle one, a majority when two agree)."""
    return np.sort(owner[cells], axis=1)[:, 1]


def dof_owners(owner: np.ndarray, dofs) -> np.ndarray:
    """Owner rank of every dof of the dof map ``dofs`` (:func:`femkit.fem.dofs.dof_map`) from the
    owners of the mesh's nodes: a vertex dof is its node's; an edge dof (P2) is owned by the
    owner of its edge's lower-numbered node (``edge_nodes[k, 0]``, original numbering), so a rank
    owns the edges it reaches first, and every rank computes the same owners."""
    if not len(dofs.edge_nodes):
        return owner
    return np.concatenate([owner, owner[dofs.edge_nodes[:, 0]]])


def build_layout(mesh, owner: np.ndarray, fixed: np.ndarray, rank: int, size: int) -> Layout:
    """Contiguous renumbering for the partition ``owner`` of the dofs (the nodes for P1, then the
    edges for P2: :func:`dof_owners`); ``fixed`` are the eliminated dofs. Elements go to ranks by
    their vertices' owners (:func:`element_owners`; the vertex dofs are the nodes)."""
    n = len(owner)
    order = np.lexsort((np.arange(n), owner))  # by owner, original order inside a rank
    node_id = np.empty(n, dtype=np.int64)
    node_id[order] = np.arange(n)
    node_offsets = np.concatenate([[0], np.cumsum(np.bincount(owner, minlength=size))])
    is_free = np.ones(n, dtype=bool)
    is_free[np.asarray(fixed, dtype=np.int64)] = False
    free_in_order = is_free[order]
    dof = np.full(n, -1, dtype=np.int64)
    dof[order[free_in_order]] = np.arange(int(free_in_order.sum()))
    dof_offsets = np.concatenate([[0], np.cumsum(np.bincount(owner[is_free], minlength=size))])
    owned = order[node_offsets[rank]:node_offsets[rank + 1]]
    elements = np.flatnonzero(element_owners(mesh.cells, owner[:mesh.n_points]) == rank)
    return Layout(rank=rank, size=size, owner=owner, node_id=node_id, node_offsets=node_offsets,
                  owned=owned, dof=dof, dof_offsets=dof_offsets, elements=elements)
