"""The heat and wave kinds on PETSc + MPI (``solver.backend: petsc``, ``mpirun -n N``).

Every rank holds the whole mesh (generated or read once on rank 0 and broadcast,
:func:`femkit.fem.distributed.broadcast_mesh`) and the whole nodal state (the schemes of
:mod:`femkit.dynamics.mol` step full vectors, unchanged). What is distributed is the work on
the matrices:

- the **partition** is the distributed Poisson one (P1: PETSc's PT-Scotch node partition and
  the contiguous renumbering of :mod:`femkit.fem.distributed.partition`, each element on the
  rank owning most of its vertices; P2: the free dofs split evenly, the cells likewise);
- each rank assembles ``M`` and ``K`` on **its own elements only** (global shape, the
  partition's part: the parts sum to the serial matrices);
- the step matrix ``A_ff = a M_ff + b K_ff`` is an MPIAIJ matrix assembled from every rank's
  part (``MatSetPreallocationCOO``/``MatSetValuesCOO``, :mod:`femkit.solvers.petsc.coo`),
  solved by one :class:`~femkit.solvers.petsc.kept.KeptKsp` **kept for the whole run** (set up
  once per distinct ``dt``: MUMPS' factor for ``direct``, BoomerAMG's hierarchy for ``pcg``),
  each iterative solve warm-started from the previous step's solution;
- products ``(a M + b K)[free] u`` are each rank's part summed over ranks (``MPI_Allreduce``),
  each solve's owned block gathered to every rank (``MPI_Allgatherv``).

The gathered result equals the serial run's to the solver's tolerance (round-off for
``direct``). Memory per rank is ``O(n)`` for the mesh and the state (as the distributed Poisson
path's mesh); the matrices and the solver's memory are split.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ...dynamics.mol import DIRECT_LIMIT, LinearSystem

__all__ = ["DistributedLinearSystem", "build_distributed_system", "petsc_step_solver"]


def petsc_step_solver(spec, dim: int, n_free: int):
    """The default step solver on PETSc: ``direct`` (MUMPS Cholesky) up to
    :data:`~femkit.dynamics.mol.DIRECT_LIMIT` free unknowns, else ``pcg`` with BoomerAMG."""
    if n_free <= DIRECT_LIMIT.get(dim, DIRECT_LIMIT[3]):
        return spec.replace(method="direct", preconditioner="none")
    return spec.replace(method="pcg", preconditioner="amg", preconditioner_options={})


class _Summed:
    """A partial matrix (this rank's elements) whose products are summed over the ranks."""

    def __init__(self, part, mpi):
        self.part, self.mpi = part, mpi

    def __matmul__(self, x):
        y = np.ascontiguousarray(self.part @ x, dtype=np.float64)
        out = np.empty_like(y)
        self.mpi.Allreduce(y, out)
        return out


@dataclass
class DistributedLinearSystem(LinearSystem):
    """:class:`~femkit.dynamics.mol.LinearSystem` with ``M`` and ``K`` this rank's part.

    Other Parameters
    ----------------
    dof : (n,) int
        Global (PETSc) unknown of each dof, ``-1`` on the Dirichlet dofs.
    dof_offsets : (size + 1,) int
        Rank ``r`` owns unknowns ``dof_offsets[r] <= d < dof_offsets[r + 1]``.
    comm : PETSc communicator
    """

    dof: np.ndarray = None
    dof_offsets: np.ndarray = None
    comm: object = None

    def __post_init__(self):
        from ...solvers.registry import petsc_names

        self.M = sp.csr_matrix(self.M)
        self.K = sp.csr_matrix(self.K)
        self.n = self.K.shape[0]
        self.fixed = np.unique(np.asarray(self.fixed, dtype=np.int64))
        self.free = np.flatnonzero(self.dof >= 0)
        self.mpi = self.comm.tompi4py()
        rank = self.comm.getRank()
        self.lo, self.hi = int(self.dof_offsets[rank]), int(self.dof_offsets[rank + 1])
        pos = np.empty(self.free.size, dtype=np.int64)   # serial free position of each unknown
        pos[self.dof[self.free]] = np.arange(self.free.size)
        self.position = pos
        self.counts = np.diff(self.dof_offsets).astype(np.int64)
        self.K_f = _Summed(self.K[self.free], self.mpi)
        self.M_f = _Summed(self.M[self.free], self.mpi)
        self.table = petsc_names()
        for key in ("factorizations", "solves", "factor_seconds", "linear_iterations",
                    "preconditioner_setups"):
            self.stats.setdefault(key, 0)

    # ------------------------------------------------------------------ operators
    def rows(self, a: float, b: float):
        key = ("rows", float(a), float(b))
        if key not in self._cache:
            part = (a * self.M_f.part + b * self.K_f.part).tocsr() if b != 0.0 else \
                (a * self.M_f.part).tocsr()
            self._cache[key] = _Summed(part, self.mpi)
        return self._cache[key]

    def _step_matrix(self, a: float, b: float):
        """The MPIAIJ ``(a M + b K)[free, free]`` from every rank's part (COO, summed)."""
        from ...solvers.petsc import coo
        from ...solvers.petsc.env import require_petsc

        PETSc = require_petsc()
        part = (a * self.M + b * self.K).tocoo() if b != 0.0 else (a * self.M).tocoo()
        N = int(self.dof_offsets[-1])
        A = PETSc.Mat().create(comm=self.comm)
        A.setSizes(((self.hi - self.lo, N), (self.hi - self.lo, N)))
        A.setType(PETSc.Mat.Type.AIJ)
        coo.set_pattern(A, self.dof[part.row], self.dof[part.col])   # -1: Dirichlet, dropped
        coo.set_values(A, part.data)
        A.setOption(PETSc.Mat.Option.SPD, True)
        return A

    def operator(self, a: float, b: float):
        """The kept ``(A_fb part, KeptKsp or diagonal)`` of ``a M + b K`` (built on first use)."""
        key = (float(a), float(b))
        op = self._ops.get(key)
        if op is not None:
            return op
        from ...solvers.petsc.kept import KeptKsp

        coupling = (self.rows(a, b).part[:, self.fixed]).tocsr()
        if b == 0.0 and self.lumped:
            op = (coupling, self.rows(a, b) @ np.ones(self.n), None)   # a diagonal's row sums
        else:
            t0 = time.perf_counter()
            s = self.solver
            ksp = KeptKsp(self._step_matrix(a, b), table=self.table, method=s.method,
                          preconditioner=None if s.preconditioner == "none" else s.preconditioner,
                          rtol=s.rtol, atol=s.atol, maxiter=s.maxiter,
                          petsc_options=s.petsc_options or None)
            self.stats["factor_seconds"] += time.perf_counter() - t0
            self.stats["factorizations" if s.method == "direct" else "preconditioner_setups"] += 1
            op = (coupling, None, ksp)
        self._ops[key] = op
        return op

    def solve(self, a: float, b: float, rhs_free: np.ndarray, t: float, *,
              values: np.ndarray | None = None) -> np.ndarray:
        """As :meth:`LinearSystem.solve`, on every rank: the owned block solved by the kept
        KSP (warm-started from the last solution), gathered to every rank."""
        coupling, diagonal, ksp = self.operator(a, b)
        g = self.g(t) if values is None else values
        x = np.empty(self.n)
        x[self.fixed] = g
        rhs = rhs_free - _Summed(coupling, self.mpi) @ g if g.size and g.any() else rhs_free
        if diagonal is not None:
            x[self.free] = rhs / diagonal
        else:
            x[self.free] = self._ksp_solve(ksp, rhs)
        self.stats["solves"] += 1
        return x

    def _ksp_solve(self, ksp, rhs: np.ndarray) -> np.ndarray:
        own = self.position[self.lo:self.hi]
        bv = ksp.A.createVecRight()
        bv.setArray(rhs[own])
        xv = getattr(ksp, "last", None)
        if xv is None:
            xv = bv.duplicate()
            xv.zeroEntries()
            ksp.last = xv
        self.stats["linear_iterations"] += ksp.solve(bv, xv)
        bv.destroy()
        by_dof = np.empty(int(self.dof_offsets[-1]))
        displs = self.dof_offsets[:-1].astype(np.int64)
        self.mpi.Allgatherv(np.ascontiguousarray(xv.getArray()), [by_dof, self.counts, displs, _double()])
        return by_dof[self.dof[self.free]]

    def quadratic_forms(self, u: np.ndarray, v: np.ndarray | None = None) -> tuple[float, float]:
        """:meth:`LinearSystem.quadratic_forms`, each rank's part summed."""
        total = np.empty(2)
        self.mpi.Allreduce(np.array(LinearSystem.quadratic_forms(self, u, v)), total)
        return float(total[0]), float(total[1])


def _double():
    from mpi4py import MPI  # femkit[petsc]: reached only after require_petsc() succeeded

    return MPI.DOUBLE


def _numbering(case, mesh, fixed: np.ndarray, comm):
    """``(dof, dof_offsets, elements)`` of this rank: P1 the distributed Poisson partition
    (:func:`~femkit.fem.distributed.partition.partition_nodes`, ``build_layout``); P2 the free
    dofs and the cells split evenly in their order."""
    from ...fem.distributed.partition import build_layout, naive_ranges, partition_nodes

    rank, size = comm.getRank(), comm.getSize()
    if case.spec.element == "P1":
        owner = partition_nodes(mesh, comm)
        lay = build_layout(mesh, owner, fixed, rank, size)
        return lay.dof, lay.dof_offsets, lay.elements
    from ...fem.dofs import dof_map

    n = dof_map(mesh, case.spec.element).n_dofs
    is_free = np.ones(n, dtype=bool)
    is_free[fixed] = False
    dof = np.full(n, -1, dtype=np.int64)
    dof[is_free] = np.arange(int(is_free.sum()))
    cells = naive_ranges(mesh.n_cells, size)
    return dof, naive_ranges(int(is_free.sum()), size), np.arange(cells[rank], cells[rank + 1])


def build_distributed_system(case, mesh, capacity: str, comm) -> DistributedLinearSystem:
    """The case's system on every rank of ``comm``: this rank's part of ``M`` and ``K``, the
    whole data (:func:`femkit.case.transient.setup.system_parts`), the default step solver of
    :func:`petsc_step_solver` when the case names none."""
    from ...solvers.petsc.failure import collective
    from .setup import _dirichlet, system_parts

    mpi = comm.tompi4py()
    fixed, _ = collective(mpi, _dirichlet, case, mesh)
    dof, offsets, elements = _numbering(case, mesh, fixed, comm)
    parts = collective(mpi, system_parts, case, mesh, capacity, elements)
    if case.spec.solver_default:
        parts["solver"] = petsc_step_solver(parts["solver"], mesh.dim, int(offsets[-1]))
    return DistributedLinearSystem(**parts, dof=dof, dof_offsets=offsets, comm=comm)
