"""A Poisson case on PETSc + MPI: ``femkit solve CASE --backend petsc`` (or ``solver:
{backend: petsc}``), run as ``mpirun -n N femkit solve ...`` (N = 1 also without mpirun).

The same stages as :func:`femkit.case.poisson.run.run_poisson`, distributed by
:mod:`femkit.fem.distributed`: the mesh is built (generated or read, validated, tags checked)
once on rank 0 and broadcast; every rank translates the case into the same
:class:`~femkit.fem.PoissonProblem` (:func:`poisson_problem`), assembles its own elements and
solves with the PETSc backend; errors against ``exact`` are reduced over ranks. Rank 0 writes
the same outputs as a serial run (``result.json`` with ``backend: petsc`` and a ``parallel``
section: ranks, KSP/PC used, partition; every stage time the maximum over ranks) and
``solution.vtu`` gathered on rank 0 when the mesh has at most :data:`GATHER_LIMIT` nodes
(``output.gather_limit``), else ``solution.pvtu`` with one ``.vtu`` piece per rank. The error
estimate (``error_estimate``, ``effectivity``) is computed on rank 0 from the gathered solution
(serially), and left out above the gather limit. ``adaptive:`` runs on the femkit backend only.
"""

from __future__ import annotations

import os
from typing import Any, Callable

from ...errors import InputError
from ..load import Case

#: Largest number of mesh nodes whose solution is gathered on rank 0 (solution.vtu); above it
#: every rank writes its piece of solution.pvtu.
GATHER_LIMIT = 2_000_000


def run_poisson_petsc(case: Case, output_dir: str | os.PathLike | None = None, quiet: bool = False,
                      write: bool = True, echo: Callable[[str], Any] | None = None):
    """Run a prepared Poisson case with ``solver.backend: petsc`` on ``PETSc.COMM_WORLD``.

    Returns a :class:`~femkit.case.poisson.run.CaseResult` on every rank (``u`` only on rank 0,
    and only when gathered). Errors: :class:`~femkit.errors.BackendUnavailableError` without
    petsc4py; input errors found on every rank are raised on every rank (exit 2, rank 0
    prints); a failure on one rank aborts the communicator.
    """
    from ...solvers.petsc import require_petsc

    PETSc = require_petsc()
    from ...solvers.petsc.failure import abort_on_error

    comm = PETSc.COMM_WORLD
    with abort_on_error(comm.tompi4py()):
        return _run(case, comm, output_dir, quiet, write, echo)


def _run(case, comm, output_dir, quiet, write, echo):
    import numpy as np
    from mpi4py import MPI  # femkit[petsc]: reached only after require_petsc() succeeded

    from ...fem.distributed.poisson import broadcast_mesh, solve_poisson
    from ...mesh import quality
    from ...solvers.petsc.failure import collective, from_root
    from ...timing import StageTimer
    from .problem import CaseResult, build_mesh, exact_gradient, nullspace_facts, poisson_problem

    mpi = comm.tompi4py()
    rank, size = comm.getRank(), comm.getSize()
    if case.spec.adaptive:  # the same check on every rank: all exit 2, rank 0 says it
        raise InputError("adaptive: adaptive refinement runs on the femkit backend only; remove "
                         "adaptive or use solver.backend: femkit")
    stage = StageTimer()
    target = None
    if write:
        from .output import output_location

        target = from_root(mpi, output_location, output_dir or case.spec.output.dir)
    with stage("mesh"):
        mesh = broadcast_mesh(lambda: build_mesh(case), comm)
        q = from_root(mpi, quality, mesh)
    problem = collective(mpi, poisson_problem, case, mesh)
    spec = case.solver
    limit = int(case.spec.output.gather_limit if case.spec.output.gather_limit is not None
                else GATHER_LIMIT)
    gather = mesh.n_points <= limit
    sol = solve_poisson(problem, method=spec.method,
                        preconditioner=spec.preconditioner,  # checked by the spec and the backend
                        rtol=spec.rtol, atol=spec.atol, maxiter=spec.maxiter,
                        petsc_options=spec.petsc_options, omega=spec.options.get("omega", 1.0),
                        exact=case.functions.get("exact.u"), grad_exact=exact_gradient(case),
                        gather=gather)
    t = sol.timings
    for name, parts in (("partition", ("partition",)),
                        ("assembly", ("pattern", "stiffness", "load")),
                        ("boundary", ("boundary_data", "dirichlet")),
                        ("solve", ("setup", "solve", "gather")), ("errors", ("errors",))):
        if any(p in t for p in parts):
            stage.times[name] = sum(t.get(p, 0.0) for p in parts)
    times = np.array([stage.times["mesh"]])
    mpi.Allreduce(times.copy(), times, op=MPI.MAX)
    stage.times["mesh"] = float(times[0])
    system = sol.system
    nnz = int(system.A.getInfo(_global_sum())["nz_used"])
    res = sol.result
    info = res.info
    parallel = {"ranks": size, "ksp_type": info["ksp_type"], "pc_type": info["pc_type"],
                "ksp_reason": info["ksp_reason"], "petsc_version": info["petsc_version"],
                "petsc_options": dict(spec.petsc_options),
                **{k: info[k] for k in ("pc_hypre_type", "factor_solver_type") if k in info},
                "partition": sol.partition, "gathered": gather, "gather_limit": limit,
                "timings_detail": dict(t), "timings_are": "the maximum over ranks per stage"}
    estimate = effectivity = indicators = None
    if sol.u is not None:  # rank 0, gathered: the serial estimator on the whole solution
        from .estimate import estimate_facts

        with stage("estimate"):
            estimate, effectivity, est = estimate_facts(case, problem, sol.u, exact_gradient(case))
        indicators = est.indicators
    elif rank == 0:
        parallel["not_computed"] = ["error_estimate (needs the gathered solution)"]
    nullspace = nullspace_facts(system)
    n_fixed = len(system.fixed)
    result = CaseResult(case=case, mesh=mesh, u=sol.u, kappa=problem.kappa, solve=res,
                        errors=sol.errors, timings=stage.times, quality=q,
                        dofs=int(system.layout.dof_offsets[-1]),
                        n_dirichlet=0 if system.mode is not None else n_fixed, nnz=nnz,
                        nullspace=nullspace, parallel=parallel, error_estimate=estimate,
                        effectivity=effectivity, indicators=indicators)
    if write:
        _write(result, target, sol, mesh, problem, comm, gather)
    if not quiet and rank == 0:
        out = echo or print
        for line in result.summary_lines():
            out(line)
        out(f"backend   petsc on {size} rank{'s' if size > 1 else ''}: KSP {parallel['ksp_type']}, "
            f"PC {parallel['pc_type']}, {parallel['ksp_reason']}; unknowns per rank "
            f"{sol.partition['unknowns_per_rank']}")
    return result


def _global_sum():
    """``MAT_GLOBAL_SUM`` for ``Mat.getInfo`` (the nonzeros of all ranks)."""
    from ...solvers.petsc import require_petsc

    return require_petsc().Mat.InfoType.GLOBAL_SUM


def _write(result, target, sol, mesh, problem, comm, gather: bool) -> None:
    """Rank 0 writes the directory (atomically); without the gathered solution every rank
    writes its piece of ``solution.pvtu`` into rank 0's temporary directory first."""
    from pathlib import Path

    from ...fem.distributed.pvtu import write_pvtu
    from .output import write_outputs

    mpi = comm.tompi4py()
    wants_pieces = not gather and result.case.spec.output.vtu

    def pieces(tmp):
        mpi.bcast(str(tmp), root=0)
        write_pvtu(tmp, "solution", mesh, sol.u_vec, sol.system.layout, comm,
                   cell_data={"kappa": problem.kappa})

    if mpi.Get_rank() == 0:
        write_outputs(result, target, write_pieces=pieces if wants_pieces else None)
    elif wants_pieces:
        tmp = Path(mpi.bcast(None, root=0))
        write_pvtu(tmp, "solution", mesh, sol.u_vec, sol.system.layout, comm,
                   cell_data={"kappa": problem.kappa})
    mpi.Barrier()
    result.output_dir = mpi.bcast(result.output_dir, root=0)
