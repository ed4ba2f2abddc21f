"""Run a ``problem: poisson`` case end to end: the one Poisson pipeline.

The case is translated once into the library's :class:`femkit.fem.PoissonProblem`
(:func:`poisson_problem`); ``femkit solve``, ``femkit check`` and every study kind assemble,
reduce and solve through it. Each stage is a small public function, so a Python user can
reuse or replace any one of them (their own mesh, coefficient, solver)::

    case = femkit.load_case("cases/poisson_unit_square.yaml", mesh={"h": 0.1})
    result = case.run(write=False)          # or step by step:
    mesh = build_mesh(case)
    problem = poisson_problem(case, mesh)   # a femkit.fem.PoissonProblem
    system = problem.assemble(case.solver.method)
    res = case.solver.solve(system.A, system.b)

Nothing is written before the mesh is built and checked against every tag the case names,
so bad input leaves no output directory behind; the output directory itself appears
atomically (see :func:`femkit.io.atomic.atomic_directory`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
from typing import Any, Callable

import numpy as np

from ...errors import CaseFileError, InputError
from ...interrupt import Interrupted, raising
from ...progress import Progress
from ..expressions import compile_case_expression
from ..frozen import freeze
from ..load import Case
from ..name_checks import check_geometry_spec, lookup, resolve_file, with_prefix
from .spec import BoundarySpec, MeshSpec, PoissonOutputSpec, PoissonSpec
from .problem import (VARIABLES, CaseResult, build_mesh, build_mesh_levels, check_dimension,
                      compute_errors, element_kappa, exact_gradient, is_pure_neumann,
                      multigrid_inputs, multigrid_overrides, nullspace_facts, on_free_nodes,
                      poisson_problem)

__all__ = ["prepare_poisson", "run_poisson", "build_mesh", "build_mesh_levels",
           "multigrid_inputs", "multigrid_overrides", "element_kappa", "poisson_problem", "compute_errors", "CaseResult"]


# ----------------------------------------------------------------------------- prepare

def _compile(case: Case, key: str, text, *, check_finite: bool = True):
    return compile_case_expression(case, key, text, VARIABLES, check_finite=check_finite)


def prepare_poisson(case: Case) -> None:
    """Check names against the registries, resolve paths, compile expressions (load time).

    Fills ``case.functions`` and ``solver.preconditioner`` (``amg`` for ``pcg``, else
    ``none``), makes ``mesh.file`` and ``output.dir`` absolute.
    """
    d = case.data
    base = case.base_dir
    if d.get("name"):
        case.name = d["name"]
    mesh = d["mesh"]
    if "file" in mesh:
        resolve_file(mesh, "mesh", base)
        if "params" in mesh or "h" in mesh:
            bad = "params" if "params" in mesh else "h"
            raise CaseFileError(f"mesh.{bad}: only used with mesh.geometry, not with mesh.file")
    else:
        check_geometry_spec(mesh, "mesh")
    from ...kinds import KINDS
    from ..specs import solver_spec

    solver = solver_spec(d["solver"], "solver",
                         default_method=KINDS.get(case.problem, "problem").default_solver)
    d["solver"] = solver.to_dict()
    from ..specs import limits_spec

    case.options = dataclasses.replace(case.options, limits=limits_spec(d.get("limits")))
    if solver.needs_hierarchy and (not mesh.get("refine") or d.get("adaptive")):
        from ...errors import HierarchyError

        what = "method 'fmg'" if solver.method == "fmg" else "preconditioner 'gmg'"
        if d.get("adaptive"):
            raise HierarchyError(f"solver: {what} needs uniformly refined nested meshes, which "
                                 f"adaptive refinement does not make; use method pcg with "
                                 f"preconditioner amg_rs")
        raise HierarchyError(f"solver: {what} needs nested meshes: give the mesh 'refine: k' "
                             f"(k >= 1), or use method pcg with preconditioner amg_rs")

    from ...fem.quadrature import QUADRATURE, TET_QUADRATURE

    if d["quadrature"]["load"] not in TET_QUADRATURE:  # the dimension is checked with the mesh
        lookup(QUADRATURE, d["quadrature"]["load"], "quadrature.load")

    coef = d["coefficient"]
    if isinstance(coef, str):
        _compile(case, "coefficient", coef)
    _compile(case, "source", d["source"])
    _prepare_nullspace(d["boundary"])
    for i, bc in enumerate(d["boundary"].get("dirichlet", [])):
        _compile(case, f"boundary.dirichlet[{i}].value", bc["value"])
    for i, bc in enumerate(d["boundary"].get("neumann", [])):
        _compile(case, f"boundary.neumann[{i}].flux", bc["flux"])
    exact = d.get("exact")
    if exact:
        _compile(case, "exact.u", exact["u"])
        for i, g in enumerate(exact.get("grad") or []):
            # Gradients of singular solutions blow up at a corner node: no finiteness check.
            _compile(case, f"exact.grad[{i}]", g, check_finite=False)

    from ...fem.estimators import ESTIMATORS

    lookup(ESTIMATORS, d["estimator"], "estimator")
    _prepare_element(d, solver)
    if d.get("adaptive"):
        from ...fem.adaptive import check_settings

        try:
            check_settings(**d["adaptive"], estimator=d["estimator"])
        except InputError as exc:
            raise with_prefix(exc, "adaptive") from None

    if "geometry" in mesh:  # a generated mesh's dimension is known now; a file's once read
        from ...mesh.geometries import GEOMETRIES

        check_dimension(case, GEOMETRIES.get(mesh["geometry"]).dim,
                        f"mesh.geometry {mesh['geometry']!r}")
    out = d["output"]
    out["dir"] = str((base / out.get("dir", os.path.join("runs", case.name))).resolve())
    bnd = d["boundary"]
    case.spec = PoissonSpec(
        mesh=MeshSpec.from_mapping(freeze(mesh)), coefficient=freeze(coef),
        boundary=BoundarySpec(tuple(freeze(list(bnd.get("dirichlet") or ()))),
                              tuple(freeze(list(bnd.get("neumann") or ()))), bnd.get("nullspace"),
                              bnd.get("compatibility_rtol")),
        load_rule=d["quadrature"]["load"], estimator=d["estimator"],
        adaptive=freeze(d["adaptive"]) if d.get("adaptive") else None, solver=solver,
        output=PoissonOutputSpec(out["dir"], bool(out["vtu"]), bool(out["xdmf"]),
                                 bool(out["plot"]), out.get("gather_limit"),
                                 out.get("compression", "none")),
        element=d["element"])


def _prepare_element(d: dict, solver) -> None:
    """``element:``: a registered element; P2 with an option it does not support is one line
    naming the option and what to use instead."""
    from ...elements import ELEMENTS

    lookup(ELEMENTS, d["element"], "element")
    if d["element"] == "P1":
        return
    name = d["element"]
    unsupported = [
        (d["estimator"] != "residual", f"estimator {d['estimator']!r}", "estimator 'residual'"),
        (bool(d["output"].get("xdmf")), "output.xdmf", "output.vtu (quadratic cells)"),
    ]
    for bad, what, instead in unsupported:
        if bad:
            raise CaseFileError(f"element {name}: {what} is not supported with {name}; use {instead} "
                                "or element P1")
    rule = d["quadrature"]["load"]
    if rule != "barycentric":
        from ...elements import get_element
        from ...fem.quadrature import QUADRATURE, TET_QUADRATURE

        need = get_element(name, 2).load_degree
        degree = (QUADRATURE.get(rule) if rule in QUADRATURE else TET_QUADRATURE.get(rule)).degree
        if degree < need:
            raise CaseFileError(f"quadrature.load {rule!r} (degree {degree}) is not exact for {name} "
                                f"products: {name} needs degree >= {need} (leave quadrature.load out "
                                "for the cheapest such rule)")


def _prepare_nullspace(bnd: dict) -> None:
    """Pure Neumann (no ``dirichlet``): fill ``nullspace`` (mean_zero) and ``compatibility_rtol``."""
    from ...fem.poisson import COMPATIBILITY_RTOL

    if bnd.get("dirichlet"):
        for key in ("nullspace", "compatibility_rtol"):
            if key in bnd:
                raise CaseFileError(f"boundary.{key}: only for pure-Neumann problems (no "
                                    "boundary.dirichlet); remove it or the Dirichlet conditions")
        return
    bnd.setdefault("nullspace", "mean_zero")
    bnd.setdefault("compatibility_rtol", COMPATIBILITY_RTOL)


# ----------------------------------------------------------------------------- run

def run_poisson(case: Case, output_dir: str | os.PathLike | None = None, quiet: bool = False,
                write: bool = True, echo: Callable[[str], Any] | None = None) -> CaseResult:
    """Run a prepared Poisson case; see the module docstring for the stages.

    Parameters
    ----------
    case : a :class:`Case` from :func:`femkit.case.load_case`.
    output_dir : overrides ``output.dir``.
    quiet : print nothing when true, else the summary (default).
    write : write ``result.json`` and the requested files (atomically) when true.
    echo : printing function (default :func:`print`).

    Returns
    -------
    CaseResult
        ``converged`` false is not an exception: the results are still written.
    """
    if case.solver.backend == "petsc":  # the same case on PETSc + MPI
        from .distributed import run_poisson_petsc

        return run_poisson_petsc(case, output_dir, quiet=quiet, write=write, echo=echo)
    from ...mesh import quality
    from ...timing import StageTimer, WallClock

    clock = WallClock()  # start-up (interpreter, imports, case file) is the process's age now
    stage = StageTimer()
    target = None
    if write:  # a bad output location is bad input: refuse it before any work is done
        from .output import output_location

        target = output_location(output_dir or case.spec.output.dir)
    stop = case.options.stop
    plan = case.options.plan
    report = Progress.planned([(st.name, st.seconds) for st in plan.stages] if plan else [],
                              case.name, quiet=quiet)

    def check_stop(where: str) -> None:  # a signal during a stage stops after it
        report.done(where, *(("refine",) if where == "mesh" else ()))  # mesh includes refine
        if stop:
            raise Interrupted(stop, stage=where)

    say = None if quiet else (echo or print)
    _compile_stage(case, None, stage, say)  # multigrid: before refinement, which has kernels too
    # stages that keep nothing partial run inside raising(): a signal stops them at once
    with raising("meshing"), stage("mesh"):
        mesh, hierarchy = build_mesh_levels(case)
    check_stop("mesh")
    _compile_stage(case, mesh, stage, say)  # a large mesh without multigrid
    from .warmup import compile_expressions

    compile_expressions(case, mesh, stage, say)  # the case's expressions (errors, estimate)
    grad = exact_gradient(case)
    run = est = None
    if case.spec.adaptive:
        from .estimate import solve_adaptive

        with raising("the adaptive loop"), stage("adaptive"):
            run = solve_adaptive(case, mesh)
        mesh, problem, u, res, est = run.mesh, run.problem, run.u, run.result, run.estimate
        system = problem.system
        dofs, nnz = int(system.A.shape[0]), int(system.A.nnz)
    else:
        problem = poisson_problem(case, mesh, scalar_kappa=True)  # a constant: one number
        with raising("assembly"), stage("assembly"):
            K, F = problem.assemble_matrices(keep_pattern=False)  # a one-off: no slot map kept
        check_stop("assembly")
        with raising("the boundary conditions"), stage("boundary"):
            system = problem.reduce(K, F, case.solver.method, overwrite=True)  # K is dropped
        del K, F  # the reduced system is what the later stages use
        check_stop("boundary")
        with raising("assembly"), stage("assembly"):  # the coarser levels' systems (fmg only)
            mg = multigrid_inputs(case, hierarchy, system)
        del hierarchy  # the coarser meshes: mg holds the levels' transfers only
        with stage("solve"):
            res = _solve(case, system, stop, **on_free_nodes(mg))  # the full transfers go first
            u = system.expand(res.x)
        del mg  # the coarser levels and their operators: not needed after the solve
        dofs, nnz = int(system.A.shape[0]), int(system.A.nnz)
        system.A = None  # nor is the matrix (the errors and the estimate work on the mesh)
        report.done("solve")
    # solution.vtu needs only the mesh and u: a writer thread writes it beside the errors and
    # the estimate, write_outputs moves it into the output directory (removed on a failure)
    from .output import solution_file

    with solution_file(case, target, mesh, u, problem.kappa) as solution:
        # after a complete solve a signal during the errors or the estimate stops at once (nothing
        # written); after an interrupted solve they run to write its last iterate
        interrupted = res.reason == "interrupted"
        with contextlib.nullcontext() if interrupted else raising("the error estimate"):
            with stage("mesh"):  # the mesh's numbers (its edges are shared with the estimator)
                q = quality(mesh)
            errors = None
            if "exact.u" in case.functions:
                with stage("errors"):  # with the gradient the estimate stage's energy error gets
                    errors = problem.errors(u, case.functions["exact.u"], grad)
            from .estimate import adaptive_facts, estimate_facts

            with stage("estimate"):
                estimate, effectivity, est = estimate_facts(case, problem, u, grad, est)
        result = CaseResult(case=case, mesh=mesh, u=u, kappa=problem.kappa, solve=res,
                            errors=errors, timings=stage.times, quality=q, dofs=dofs,
                            n_dirichlet=len(system.fixed) if not is_pure_neumann(case) else 0,
                            nnz=nnz, nullspace=nullspace_facts(system), error_estimate=estimate,
                            effectivity=effectivity, indicators=est.indicators,
                            adaptive=adaptive_facts(run) if run is not None else None,
                            interrupted=stop.name if interrupted else None, clock=clock)
        if write:
            from .output import write_outputs

            write_outputs(result, target, solution=solution)
    if not quiet:
        out = echo or print
        for line in result.summary_lines():
            out(line)
        for note in case.notes:  # e.g. a mesh file's unused nodes
            out(f"note      {note}")
        out(clock.summary(result.timings))
    return result


def _compile_stage(case: Case, mesh, stage, echo) -> None:
    """The first run after an install compiles the kernels it needs ahead, in its own
    ``compile`` stage (not inside assembly and solve), saying so on the terminal (``echo``)."""
    from .cost import case_dimension
    from .warmup import dimensions, must_compile, needs_kernels, start_numba, warm_up

    multigrid = case.solver.needs_hierarchy
    element = case.spec.element
    if needs_kernels(mesh, multigrid, element):
        start_numba(stage)  # numba's own start-up, once, in its own stage
    dims = dimensions(mesh.dim if mesh is not None else case_dimension(case))
    if must_compile(mesh, multigrid, dims, element):
        with stage("compile"):
            seconds = warm_up(echo, multigrid, dims)
        if echo is not None:
            echo(f"compiled in {seconds:.1f} s (stage 'compile'; the next runs load them)")


def _solve(case: Case, system, stop, **mg):
    """Solve the reduced system (``mg``: multigrid inputs); a stop request during an iterative
    solve ends it with the last iterate as a not-converged result (``reason: interrupted``)
    that is written like any other."""
    if stop is None:
        return case.solver.solve(system.A, system.b, **mg)
    from ...interrupt import stopping_callback
    from ...solvers.core.result import SolveResult

    try:
        return case.solver.solve(system.A, system.b, callback=stopping_callback(stop), **mg)
    except Interrupted as exc:
        r = system.b - system.A @ exc.x
        bn = float(np.linalg.norm(system.b))
        s = case.solver
        return SolveResult(x=exc.x, converged=False, iterations=exc.iteration,
                           residuals=np.array([]), reason="interrupted",
                           message=f"interrupted by {stop.name} after {exc.iteration} iterations",
                           true_residual=float(np.linalg.norm(r)), rhs_norm=bn,
                           tolerance=max(s.rtol * bn, s.atol), method=s.method,
                           preconditioner=s.preconditioner)

