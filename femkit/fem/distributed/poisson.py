"""A :class:`femkit.fem.PoissonProblem` solved on all MPI ranks with the PETSc backend.

The mesh is read or generated **once, on rank 0, and broadcast** (:func:`broadcast_mesh`):
gmsh's output is not guaranteed to be identical across processes (threads, versions), and a
node numbering that differed between ranks would silently corrupt the assembly; reading a
file on every rank would also multiply the I/O. Every rank then holds the whole mesh
(``points``, ``triangles``, tags: ~56 bytes per node for a triangle mesh), which is the
memory limit of this design (see "Scale-out" in docs/modules.md); the matrix, the
vectors, the partition's work and the solver's memory are distributed.

Steps (all ranks): partition the nodes (:mod:`.partition`), renumber them contiguously,
eliminate Dirichlet nodes, assemble own elements into an MPIAIJ matrix (:mod:`.assembly`),
solve with :func:`.backend.ksp_solve`, rebuild the nodal solution, compute errors against
the exact solution on own elements and reduce them, gather the solution to rank 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...solvers.petsc.backend import ksp_solve
from ...solvers.registry import petsc_names
from ...solvers.petsc.env import require_petsc
from ...solvers.petsc.failure import collective, from_root
from ...solvers.core.result import SolveResult
from ...timing import StageTimer
from ..norms import error_norms
from ..poisson import mean_shift_parts
from .assembly import (DistributedSystem, assemble_poisson, gather_nodal, nodal_solution,
                       values_at)
from .partition import DEFAULT_PARTITIONER, build_layout, dof_owners, partition_nodes


def broadcast_mesh(make_mesh, comm=None):
    """``make_mesh()`` run on rank 0 (generate or read), the mesh broadcast to every rank.

    An error on rank 0 (bad file, gmsh failure) is raised on every rank.
    """
    comm = comm or require_petsc().COMM_WORLD
    return from_root(comm.tompi4py(), make_mesh)


@dataclass
class DistributedSolution:
    """Outcome of :func:`solve_poisson`.

    Attributes
    ----------
    u : ndarray or None
        Nodal solution in original node order on rank 0 (``None`` on other ranks, or when
        ``gather=False``).
    result : SolveResult
        ``x`` is this rank's part of the unknowns; ``info`` has ``backend``, ``ranks``,
        ``ksp_type``, ``pc_type``, ``ksp_reason``.
    errors : dict or None
        ``L2``, ``H1_semi``, ``max_nodal`` against the exact solution, reduced over ranks.
    timings : dict
        Seconds per stage, the maximum over ranks.
    partition : dict
        Nodes, unknowns and elements per rank, the partitioner used.
    system : DistributedSystem
        The PETSc matrix and vectors (for inspection; e.g. :func:`.assembly.gather_matrix`).
    u_vec : PETSc.Vec
        The nodal solution, distributed (node numbering of ``system.layout``).
    """

    u: np.ndarray | None
    result: SolveResult
    errors: dict | None
    timings: dict
    partition: dict
    system: DistributedSystem = None
    u_vec: object = None
    extras: dict = field(default_factory=dict)


def solve_poisson(problem, *, method: str = "pcg", preconditioner: str | None = None,
                  rtol: float | None = None, atol: float | None = None, maxiter: int | None = None,
                  petsc_options: dict | None = None, omega: float = 1.0, exact=None,
                  grad_exact=None, error_order: int = 5, gather: bool = True,
                  partitioner: str = DEFAULT_PARTITIONER, comm=None) -> DistributedSolution:
    """Assemble and solve ``problem`` on every rank of ``comm`` (default ``PETSc.COMM_WORLD``).

    Parameters
    ----------
    problem : PoissonProblem
        Built on every rank from the same (broadcast) mesh and data.
    method, preconditioner, rtol, atol, maxiter, petsc_options, omega
        As in :func:`.backend.ksp_solve` (femkit names mapped onto KSP/PC).
    exact, grad_exact : callable, optional
        Exact solution and gradient: errors computed on each rank's elements and reduced
        (pure Neumann: modulo the constant, as :meth:`PoissonProblem.errors`).
    gather : bool
        Gather the nodal solution to rank 0 (``u``).
    partitioner : str
        PETSc ``MatPartitioning`` type.

    Returns
    -------
    DistributedSolution
    """
    PETSc = require_petsc()
    comm = comm or PETSc.COMM_WORLD
    mpi = comm.tompi4py()
    rank, size = comm.getRank(), comm.getSize()
    timer = StageTimer()
    times = timer.times

    mesh = problem.mesh
    with timer("boundary_data"):
        if problem.nullspace is None:
            fixed, values = collective(mpi, problem.dirichlet_data)
        else:  # pure Neumann: pin one node (to pin_value in "pin" mode, else 0, then shifted)
            fixed = np.array([problem.pin_node], dtype=np.int64)
            values = np.array([problem.pin_value if problem.nullspace == "pin" else 0.0])
    with timer("partition"):
        owner = dof_owners(partition_nodes(mesh, comm, method=partitioner), problem.dofs)
        layout = build_layout(mesh, owner, fixed, rank, size)
    system = collective(mpi, assemble_poisson, problem, layout, comm, fixed, values, timer=timer)
    result, x = ksp_solve(system.A, system.b, table=petsc_names(), method=method,
                          preconditioner=preconditioner,
                          rtol=rtol, atol=atol, maxiter=maxiter, petsc_options=petsc_options,
                          omega=omega)
    times["setup"] = result.setup_time
    times["solve"] = result.solve_time
    u_vec = nodal_solution(system, x, comm)
    errors = None
    if exact is not None:
        with timer("errors"):
            errors = parallel_errors(mesh, u_vec, layout, comm, exact, grad_exact, error_order,
                                     modulo_constant=problem.nullspace is not None,
                                     element=problem.element.name)
    u = None
    if gather:
        with timer("gather"):
            u = gather_nodal(u_vec, layout, comm)
    stages = sorted(times)
    tmax = np.array([times[s] for s in stages])
    mpi.Allreduce(tmax.copy(), tmax, op=_max_op())
    counts = mpi.allgather((layout.n_local_nodes, layout.n_local_dofs, len(layout.elements)))
    partition = {"partitioner": partitioner if size > 1 else "none", "ranks": size,
                 "nodes_per_rank": [c[0] for c in counts],
                 "unknowns_per_rank": [c[1] for c in counts],
                 "elements_per_rank": [c[2] for c in counts]}
    return DistributedSolution(u=u, result=result, errors=errors,
                               timings=dict(zip(stages, map(float, tmax))), partition=partition,
                               system=system, u_vec=u_vec)


def _max_op():
    from mpi4py import MPI  # femkit[petsc]: reached only after require_petsc() succeeded

    return MPI.MAX


def parallel_errors(mesh, u_vec, layout, comm, exact, grad_exact=None, order: int = 5, *,
                    modulo_constant: bool = False, element: str = "P1") -> dict:
    """:func:`femkit.fem.error_norms` (P2: :func:`femkit.fem.lagrange.element_error_norms`) on
    each rank's elements, reduced over ranks (squared integrals summed, nodal maxima maximised);
    the dofs of own elements that other ranks own are fetched with a VecScatter.
    ``modulo_constant`` (pure Neumann): errors of ``u - c`` with ``int (u - c - exact) = 0``, the
    integrals summed over ranks (:func:`femkit.fem.poisson.mean_shift_parts`), as
    :meth:`PoissonProblem.errors` does."""
    from mpi4py import MPI  # femkit[petsc]: reached only after require_petsc() succeeded

    from ..dofs import dof_map

    mpi = comm.tompi4py()
    own = layout.elements
    dofs = dof_map(mesh, element)
    nodes = np.unique(dofs.cells[own])
    u = np.zeros(dofs.n_dofs)
    u[nodes] = values_at(u_vec, layout, nodes, comm)
    if modulo_constant:
        parts = np.array(collective(mpi, _shift_parts, mesh, u, exact, order, own, element))
        mpi.Allreduce(parts.copy(), parts, op=MPI.SUM)
        u[nodes] -= (parts[0] - parts[1]) / parts[2]
    if element == "P1":
        local = collective(mpi, error_norms, mesh, u, exact, grad_exact, order=order,
                           elements=own, squared=True)
    else:
        from ..lagrange import element_error_norms

        local = collective(mpi, element_error_norms, mesh, u, exact, grad_exact, element=element,
                           order=order, elements=own, squared=True)
    sums = mpi.allreduce(np.array([local["L2"], local["H1_semi"] or 0.0]), op=MPI.SUM)
    worst = mpi.allreduce(local["max_nodal"], op=MPI.MAX)
    return {"L2": float(np.sqrt(sums[0])),
            "H1_semi": float(np.sqrt(sums[1])) if grad_exact is not None else None,
            "max_nodal": float(worst)}


def _shift_parts(mesh, u, exact, order: int, own, element: str) -> tuple:
    """``(int u_h, int u, measure)`` over the cells ``own`` (:func:`mean_shift_parts`; P2:
    ``int u_h`` by the dof weights of those cells, as :meth:`PoissonProblem.errors`)."""
    if element == "P1":
        return mean_shift_parts(mesh, u, exact, order=order, elements=own)
    from ..lagrange import dof_weights

    _, ue, area = mean_shift_parts(mesh, np.zeros(mesh.n_points), exact, order=order, elements=own)
    return float(dof_weights(mesh, element, elements=own) @ u), ue, area
