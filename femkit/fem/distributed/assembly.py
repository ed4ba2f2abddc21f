"""Partitioned assembly of a P1 or P2 Poisson problem into PETSc objects.

Every rank holds the whole mesh (read or generated once on rank 0 and broadcast; see
:mod:`.poisson`), assembles only its own elements with femkit's kernels
(:func:`femkit.fem.local_stiffness`, :func:`femkit.fem.assemble_load` with ``elements=``; P2:
:func:`femkit.fem.forms.local_matrices`, :func:`femkit.fem.lagrange.element_load`, over the dof
map's cells, the unknowns being its dofs: :func:`.partition.dof_owners`) and hands the
``(rows, cols, values)`` triplets to an MPIAIJ matrix through
``MatSetPreallocationCOO``/``MatSetValuesCOO`` (:mod:`.coo`); PETSc sends entries owned by
other ranks to them and sums repeated entries. Dirichlet nodes are eliminated (their rows and
columns get index ``-1``, which PETSc drops; their values are lifted to the right-hand side),
so the operator is ``K[free, free]``, symmetric positive definite, exactly the serial
:func:`femkit.fem.apply_dirichlet` matrix up to the renumbering. Pure-Neumann problems pin
one node (the iterative form of :func:`femkit.fem.poisson.pure_neumann_system`) after the same
compatibility check, computed from sums reduced over ranks.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..load import assemble_load
from ..p1_stiffness import local_stiffness
from ..poisson import compatibility_facts, node_weights
from ...solvers.petsc import coo
from ...solvers.petsc.env import require_petsc
from .partition import Layout


@dataclass
class DistributedSystem:
    """The reduced system on all ranks: ``A`` (MPIAIJ over the unknowns), ``b``, and what is
    needed to rebuild the nodal solution (``g``: Dirichlet values by original node; ``mode`` and
    ``weights`` for pure Neumann)."""

    A: object
    b: object
    layout: Layout
    g: np.ndarray
    mode: str | None = None
    weights: object = None
    compatibility: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    bordered: bool = False  # never: pure Neumann pins a node (as the serial iterative path)

    @property
    def fixed(self) -> np.ndarray:
        """Original ids of the eliminated nodes (Dirichlet, or the pinned node), sorted."""
        return np.flatnonzero(self.layout.dof < 0)


def node_vector(layout: Layout, comm):
    """A PETSc vector over all nodes in the new (contiguous) numbering, zeroed."""
    PETSc = require_petsc()
    v = PETSc.Vec().createMPI((layout.n_local_nodes, int(layout.node_offsets[-1])), comm=comm)
    v.zeroEntries()
    return v


def add_nodal(vec, layout: Layout, nodes: np.ndarray, values: np.ndarray) -> None:
    """Add ``values`` at original ``nodes`` (any rank's) into a node vector (assembled later)."""
    PETSc = require_petsc()
    vec.setValues(layout.node_id[nodes].astype(PETSc.IntType), values,
                  addv=PETSc.InsertMode.ADD_VALUES)


def assemble_matrix(problem, layout: Layout, comm, local: np.ndarray, *, timer=None):
    """The MPIAIJ matrix ``K[free, free]`` from this rank's local matrices ``local`` (k, w, w):
    w = 3 on triangles, 4 on tetrahedra (P1), 6 and 10 (P2, the dof map's cells);
    ``timer("pattern")`` times the one-off pattern analysis (MatSetPreallocationCOO),
    ``timer("stiffness")`` the values (MatSetValuesCOO)."""
    import contextlib

    PETSc = require_petsc()
    timer = timer or (lambda stage: contextlib.nullcontext())
    tri = problem.dofs.cells[layout.elements]
    d = layout.dof[tri].astype(PETSc.IntType)  # (k, 3 or 4), -1 on eliminated nodes
    nv = tri.shape[1]
    N = int(layout.dof_offsets[-1])
    A = PETSc.Mat().create(comm=comm)
    A.setSizes(((layout.n_local_dofs, N), (layout.n_local_dofs, N)))
    A.setType(PETSc.Mat.Type.AIJ)
    with timer("pattern"):  # local[k, a, b] sits at (d[k, a], d[k, b])
        coo.set_pattern(A, np.repeat(d, nv, axis=1).ravel(), np.tile(d, (1, nv)).ravel())
    with timer("stiffness"):
        coo.set_values(A, local.reshape(-1))
    A.setOption(PETSc.Mat.Option.SPD, True)
    return A


def assemble_poisson(problem, layout: Layout, comm, fixed: np.ndarray, values: np.ndarray,
                     *, timer=None) -> DistributedSystem:
    """Assemble ``problem`` (a :class:`femkit.fem.PoissonProblem`) on this rank's elements.

    ``fixed``/``values``: Dirichlet nodes and values (for pure Neumann: the pinned node).
    ``timer(stage)`` is a context manager recording stage times (optional).
    """
    import contextlib

    PETSc = require_petsc()
    timer = timer or (lambda stage: contextlib.nullcontext())
    mesh = problem.mesh
    own = layout.elements
    tri = problem.dofs.cells[own]
    with timer("stiffness"):
        local = _local_stiffness(problem, own)
    A = assemble_matrix(problem, layout, comm, local, timer=timer)
    with timer("load"):
        touched = np.unique(tri)
        F_src = _load(problem, own)[touched]
        mine = layout.owned
        F_flux = problem.neumann_vector()[mine] if problem.neumann else np.zeros(len(mine))
        F = node_vector(layout, comm)
        add_nodal(F, layout, touched, F_src)
        add_nodal(F, layout, mine, F_flux)
        F.assemble()
    g = np.zeros(problem.n_dofs)
    g[fixed] = values
    mode, w, facts = problem.nullspace, None, {}
    with timer("dirichlet"):
        if mode is not None:
            mpi = comm.tompi4py()
            w = node_vector(layout, comm)
            add_nodal(w, layout, touched, _weights(problem, own)[touched])
            w.assemble()
            # sum |F_source| needs the assembled source alone: F - flux on owned nodes
            F_arr = F.getArray()
            src_abs = float(np.abs(F_arr - F_flux).sum())
            sums = mpi.allreduce(np.array([float(F_src.sum()), float(F_flux.sum()),
                                           src_abs + float(np.abs(F_flux).sum())]))
            # element loads summed per rank: the source integral is the sum of F_src over ranks
            facts = compatibility_facts(float(sums[0]), float(sums[1]), float(sums[2]),
                                        problem.compatibility_rtol)
            F.axpy(-float(sums[0] + sums[1]) / w.sum(), w)
        lift = -np.einsum("kab,kb->ka", local, g[tri])
        has = np.any(np.isin(tri, fixed), axis=1) if len(fixed) else np.zeros(len(tri), bool)
        if has.any():
            add_nodal(F, layout, tri[has].ravel(), lift[has].ravel())
        F.assemble()
        b = PETSc.Vec().createMPI((layout.n_local_dofs, int(layout.dof_offsets[-1])), comm=comm)
        b.setArray(F.getArray()[layout.owned_free])
    F.destroy()
    return DistributedSystem(A=A, b=b, layout=layout, g=g, mode=mode, weights=w,
                             compatibility=facts)


def _local_stiffness(problem, own: np.ndarray) -> np.ndarray:
    """Local stiffness matrices (k, w, w) of the cells ``own``: P1's own kernel, else the
    element-generic one (:func:`femkit.fem.forms.local_matrices`)."""
    if problem.element.name == "P1":
        return local_stiffness(problem.mesh, problem.kappa, elements=own)
    from ..forms import local_matrices

    return local_matrices(problem.mesh, "stiffness", problem.kappa, element=problem.element, elements=own)


def _load(problem, own: np.ndarray) -> np.ndarray:
    """The source's load vector (n_dofs,) of the cells ``own`` (P1's rule, or the element's
    default rule unless the problem names another, as :meth:`PoissonProblem.assemble_matrices`)."""
    if problem.element.name == "P1":
        return assemble_load(problem.mesh, problem.f, rule=problem.load_rule, elements=own)
    from ..lagrange import element_load

    rule = None if problem.load_rule == "barycentric" else problem.load_rule
    return element_load(problem.mesh, problem.f, problem.element, rule=rule, elements=own)


def _weights(problem, own: np.ndarray) -> np.ndarray:
    """``int phi_i`` (n_dofs,) over the cells ``own``."""
    if problem.element.name == "P1":
        return node_weights(problem.mesh, elements=own)
    from ..lagrange import dof_weights

    return dof_weights(problem.mesh, problem.element, elements=own)


def nodal_solution(system: DistributedSystem, x, comm):
    """The nodal solution vector (node numbering): unknowns from ``x``, ``g`` on eliminated
    nodes; pure Neumann ``mean_zero``: shifted to ``int u dx = 0`` (``w . u = 0``)."""
    lay = system.layout
    u = node_vector(lay, comm)
    arr = system.g[lay.owned].copy()
    arr[lay.owned_free] = x.getArray()
    u.setArray(arr)
    if system.mode == "mean_zero":
        u.shift(-u.dot(system.weights) / system.weights.sum())
    return u


def values_at(u, layout: Layout, nodes: np.ndarray, comm) -> np.ndarray:
    """Values of the node vector ``u`` at original ``nodes`` (any rank's), by a VecScatter."""
    PETSc = require_petsc()
    idx = PETSc.IS().createGeneral(layout.node_id[nodes].astype(PETSc.IntType), comm=PETSc.COMM_SELF)
    out = PETSc.Vec().createSeq(len(nodes), comm=PETSc.COMM_SELF)
    sc = PETSc.Scatter().create(u, idx, out, None)
    sc.scatter(u, out, addv=PETSc.InsertMode.INSERT_VALUES, mode=PETSc.ScatterMode.FORWARD)
    vals = out.getArray().copy()
    for obj in (sc, out, idx):
        obj.destroy()
    return vals


def gather_nodal(u, layout: Layout, comm, root: int = 0) -> np.ndarray | None:
    """The whole nodal vector in original node order on ``root`` (``None`` elsewhere)."""
    mpi = comm.tompi4py()
    parts = mpi.gather((layout.owned, u.getArray().copy()), root=root)
    if mpi.Get_rank() != root:
        return None
    out = np.empty(len(layout.node_id))
    for nodes, vals in parts:
        out[nodes] = vals
    return out


def gather_matrix(A, layout: Layout, comm, root: int = 0):
    """The assembled matrix on ``root`` as scipy CSR indexed like the serial reduced system
    (unknowns in increasing original node order); ``None`` on the other ranks."""
    import scipy.sparse as sp

    mpi = comm.tompi4py()
    indptr, indices, data = A.getValuesCSR()
    start = int(layout.dof_offsets[layout.rank])
    rows = start + np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))
    parts = mpi.gather((rows, np.asarray(indices, dtype=np.int64), data.copy()), root=root)
    if mpi.Get_rank() != root:
        return None
    free = np.flatnonzero(layout.dof >= 0)  # original ids, sorted: the serial order
    serial_of_dof = np.empty(len(free), dtype=np.int64)
    serial_of_dof[layout.dof[free]] = np.arange(len(free))
    r = np.concatenate([p[0] for p in parts])
    c = np.concatenate([p[1] for p in parts])
    v = np.concatenate([p[2] for p in parts])
    M = sp.csr_matrix((v, (serial_of_dof[r], serial_of_dof[c])), shape=(len(free), len(free)))
    M.sort_indices()
    return M
