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

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ...errors import CaseFileError, ExpressionError, InputError
from ...interrupt import Interrupted
from ...progress import Progress
from ..expressions import compile_expression
from ..load import Case
from ..names import check_geometry_spec, lookup, resolve_file, with_prefix

__all__ = ["prepare_poisson", "run_poisson", "build_mesh", "build_mesh_levels",
           "multigrid_inputs", "multigrid_overrides", "element_kappa", "poisson_problem", "compute_errors", "CaseResult"]


# ----------------------------------------------------------------------------- prepare

def _compile(case: Case, key: str, text, *, check_finite: bool = True):
    try:
        fn = compile_expression(text, ("x", "y"), case.data.get("constants") or {},
                                check_finite=check_finite)
    except ExpressionError as exc:
        raise ExpressionError(f"{key}: {exc}") from None
    fn.label = key
    case.functions[key] = fn
    return fn


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
    from ...solvers.defaults import DEFAULT_METHOD
    from ..specs import solver_spec

    case.solver = solver_spec(d["solver"], "solver", default_method=DEFAULT_METHOD["poisson"])
    d["solver"] = case.solver.to_dict()
    from ..specs import limits_spec

    case.run_options["limits"] = limits_spec(d.get("limits"))
    if case.solver.needs_hierarchy and (not mesh.get("refine") or d.get("adaptive")):
        from ...errors import HierarchyError

        what = "method 'fmg'" if case.solver.method == "fmg" else "preconditioner 'gmg'"
        if d.get("adaptive"):
            raise HierarchyError(f"solver: {what} needs uniformly refined nested meshes, which "
                                 f"adaptive refinement does not make; use method pcg with "
                                 f"preconditioner amg_rs")
        raise HierarchyError(f"solver: {what} needs nested meshes: give the mesh 'refine: k' "
                             f"(k >= 1), or use method pcg with preconditioner amg_rs")

    from ...fem.quadrature import QUADRATURE

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
    if d.get("adaptive"):
        from ...fem.adaptive import check_settings

        try:
            check_settings(**d["adaptive"], estimator=d["estimator"])
        except InputError as exc:
            raise with_prefix(exc, "adaptive") from None

    out = d["output"]
    out["dir"] = str((base / out.get("dir", os.path.join("runs", case.name))).resolve())


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


# ----------------------------------------------------------------------------- stages

#: Refined meshes with at least this many triangles are renumbered for memory locality
#: (reverse Cuthill-McKee on the coarse mesh, midpoints next to their edges: see
#: :class:`femkit.mesh.MeshHierarchy`); at 3.7M triangles assembly is 1.6-3x and an fmg solve
#: 2-3x faster, at 0.9M it makes no difference (docs/benchmarks.md).
RENUMBER_MIN_TRIANGLES = 2_000_000


def build_mesh(case: Case, *, h: float | None = None):
    """Generate or read the mesh, refine, validate, and check every tag the case names.

    ``h`` replaces ``mesh.h`` of a generated mesh (studies sweep it); a mesh file ignores it.
    """
    return build_mesh_levels(case, h=h)[0]


def build_mesh_levels(case: Case, *, h: float | None = None):
    """:func:`build_mesh` and the :class:`~femkit.mesh.MeshHierarchy` of its refinement when the
    case's solver is geometric multigrid (``None`` otherwise): ``(mesh, hierarchy)``."""
    from ...mesh import MeshHierarchy, check_tags, generate, read_mesh, refine, validate
    from ..cost import check_mesh_fits

    spec = case.data["mesh"]
    where = f"mesh.file {spec['file']}" if "file" in spec else f"mesh.geometry {spec['geometry']}"

    force = case.run_options.get("force", False)  # --force also passes the memory guard
    try:
        if "file" in spec:
            mesh = read_mesh(spec["file"])
        else:
            hv, params = spec["h"] if h is None else h, spec.get("params") or {}
            check_mesh_fits(geometry=spec["geometry"], h=hv, params=params, force=force)
            mesh = generate(spec["geometry"], hv, **params)
        mesh = validate(mesh)
    except InputError as exc:
        raise with_prefix(exc, where) from None
    hierarchy = None
    k = spec.get("refine") or 0
    if k:
        check_mesh_fits(triangles=mesh.n_triangles, refine=k, force=force)  # before numpy allocates
        big = mesh.n_triangles * 4 ** k >= RENUMBER_MIN_TRIANGLES
        if big or case.solver.needs_hierarchy:
            levels = MeshHierarchy.from_refinement(mesh, k, renumber="rcm" if big else "none")
            mesh = levels.finest
            hierarchy = levels if case.solver.needs_hierarchy else None
        else:
            mesh = refine(mesh, k)
    bnd = case.data["boundary"]
    for kind in ("dirichlet", "neumann"):
        for i, bc in enumerate(bnd.get(kind, [])):
            tags = [t for t in bc["tags"] if not _is_whole_boundary(mesh, t)]
            if tags:
                try:
                    check_tags(mesh, tags, kind="boundary")
                except InputError as exc:
                    raise with_prefix(exc, f"boundary.{kind}[{i}].tags") from None
    coef = case.data["coefficient"]
    if isinstance(coef, dict):
        try:
            check_tags(mesh, list(coef["regions"]), kind="cell")
        except InputError as exc:
            raise with_prefix(exc, "coefficient.regions") from None
    return mesh, hierarchy


def multigrid_inputs(case: Case, hierarchy, system) -> dict:
    """What geometric multigrid needs at solve time, as :meth:`SolverSpec.solve` overrides:
    the hierarchy and the free nodes; for ``fmg`` with Dirichlet conditions also the reduced
    systems of the coarser meshes (their own right-hand sides and Dirichlet values, see
    :func:`femkit.solvers.fmg.fmg`). Empty for every other solver."""
    spec = case.solver
    if not spec.needs_hierarchy:
        return {}
    levels = None
    if spec.method == "fmg" and not is_pure_neumann(case):
        levels = [poisson_problem(case, m).assemble(spec.method) for m in hierarchy.meshes[:-1]]
    return multigrid_overrides(spec, hierarchy, system.free, levels)


def multigrid_overrides(spec, hierarchy, free, levels=None) -> dict:
    """The :meth:`SolverSpec.solve` overrides of geometric multigrid: ``{"options": ...}`` for
    ``method: fmg`` (with the coarser levels' own systems ``levels`` when given),
    ``{"preconditioner_options": ...}`` for ``preconditioner: gmg``, ``{}`` otherwise. The one
    place the case pipeline and the studies turn a hierarchy into solver arguments."""
    if not spec.needs_hierarchy:
        return {}
    mg = {"hierarchy": hierarchy, "free": free}
    if spec.method != "fmg":
        return {"preconditioner_options": mg}
    if levels is not None:
        mg["levels"] = list(levels)
    return {"options": mg}


def _is_whole_boundary(mesh, tag) -> bool:
    """``boundary`` names the whole (topological) boundary of a mesh without such a group."""
    return tag == "boundary" and "boundary" not in mesh.tag_names


def element_kappa(case: Case, mesh) -> np.ndarray:
    """Per-triangle coefficient values (constant, expression at barycentres, or region table)."""
    from ...fem.coefficients import element_coefficient

    coef = case.data["coefficient"]
    if isinstance(coef, dict):
        from ...mesh import check_tags

        values = np.full(mesh.n_triangles, float(coef.get("default", np.nan)))
        for name, value in coef["regions"].items():
            (tag,) = check_tags(mesh, [name], kind="cell")
            values[mesh.cell_tags == tag] = float(value)
        missing = np.flatnonzero(np.isnan(values))
        if missing.size:
            tags = sorted(set(mesh.cell_tags[missing].tolist()))
            raise CaseFileError(
                f"coefficient.regions: {missing.size} triangles (cell tags {tags}) are in no "
                f"listed region; add them or give coefficient.default")
        return values
    kappa = case.functions.get("coefficient", coef)
    try:
        return element_coefficient(mesh, kappa, name="coefficient")
    except ExpressionError:
        raise
    except InputError as exc:
        raise with_prefix(exc, "coefficient") from None


def _tags(mesh, tags: list):
    """Boundary-condition tags for the library: ``None`` (the whole boundary, found
    topologically) when the list names the whole boundary of a mesh without such a group."""
    named = [t for t in tags if not _is_whole_boundary(mesh, t)]
    return named if len(named) == len(tags) else None


def poisson_problem(case: Case, mesh, *, load_rule: str | None = None):
    """The case on ``mesh`` as a :class:`femkit.fem.PoissonProblem` (the one translation).

    Dirichlet entries naming the whole boundary together with other tags cover both (a later
    entry wins on shared nodes); a Neumann entry naming the whole boundary takes each boundary
    edge once. Pure Neumann with ``nullspace: pin`` pins node 0 to the exact solution's value
    there when ``exact`` is given, else to 0.
    """
    from ...fem import PoissonProblem

    d = case.data
    bnd = d["boundary"]
    dirichlet = []
    for i, bc in enumerate(bnd.get("dirichlet", [])):
        g = case.functions[f"boundary.dirichlet[{i}].value"]
        named = [t for t in bc["tags"] if not _is_whole_boundary(mesh, t)]
        if len(named) < len(bc["tags"]):
            dirichlet.append((None, g))
        if named:
            dirichlet.append((named, g))
    neumann = [(_tags(mesh, bc["tags"]), case.functions[f"boundary.neumann[{i}].flux"])
               for i, bc in enumerate(bnd.get("neumann", []))]
    extra = {}
    if not dirichlet:
        extra = dict(nullspace=bnd["nullspace"], compatibility_rtol=bnd["compatibility_rtol"])
        if bnd["nullspace"] == "pin" and "exact.u" in case.functions:
            x0, y0 = mesh.points[0]
            u0 = case.functions["exact.u"](np.array([x0]), np.array([y0]))
            extra["pin_value"] = float(np.asarray(u0).ravel()[0])
    return PoissonProblem(mesh, element_kappa(case, mesh), case.functions["source"],
                          dirichlet=dirichlet, neumann=neumann,
                          load_rule=load_rule or d["quadrature"]["load"], **extra)


def is_pure_neumann(case: Case) -> bool:
    """True when the case has no Dirichlet condition (``u`` fixed only up to a constant)."""
    return not case.data["boundary"].get("dirichlet")


def exact_gradient(case: Case):
    """``grad u`` of ``exact`` as one callable ``(x, y) -> (gx, gy)``, or None."""
    if "exact.grad[0]" not in case.functions:
        return None
    gx, gy = case.functions["exact.grad[0]"], case.functions["exact.grad[1]"]

    def grad(x, y):
        return gx(x, y), gy(x, y)

    return grad


def compute_errors(case: Case, problem, u: np.ndarray, *, order: int = 5) -> dict | None:
    """Error norms against ``exact`` (None when the case gives no exact solution); pure
    Neumann: modulo the constant (:meth:`femkit.fem.PoissonProblem.errors`)."""
    if "exact.u" not in case.functions:
        return None
    return problem.errors(u, case.functions["exact.u"], exact_gradient(case), order=order)


# ----------------------------------------------------------------------------- result

@dataclass
class CaseResult:
    """Everything a Poisson run produced (arrays in memory, facts in :meth:`to_dict`)."""

    case: Case
    mesh: Any
    u: np.ndarray
    kappa: np.ndarray
    solve: Any
    errors: dict | None
    timings: dict
    quality: dict
    dofs: int
    n_dirichlet: int
    nnz: int
    output_dir: Path | None = None
    files: list = field(default_factory=list)
    nullspace: dict | None = None
    error_estimate: dict | None = None
    effectivity: float | None = None
    indicators: np.ndarray | None = None
    adaptive: dict | None = None
    parallel: dict | None = None
    interrupted: str | None = None

    @property
    def converged(self) -> bool:
        return bool(self.solve.converged)

    def to_dict(self) -> dict:
        """The content of ``result.json`` (keys documented in docs/case-files.md)."""
        from ..._version import __version__

        spec = self.case.data["mesh"]
        mesh_info = {k: self.quality.get(k) for k in (
            "n_points", "n_triangles", "h_max", "h_min", "h_mean", "min_angle",
            "max_aspect_ratio", "area")}
        mesh_info["n_points"] = self.mesh.n_points
        mesh_info["n_triangles"] = self.mesh.n_triangles
        mesh_info["source"] = (spec["file"] if "file" in spec else
                               f"geometry {spec['geometry']} h={spec['h']}")
        mesh_info["refine"] = spec.get("refine", 0)
        return {
            "case": self.case.name,
            "problem": self.case.problem,
            "case_file": str(self.case.path) if self.case.path else None,
            "femkit_version": __version__,
            "mesh": mesh_info,
            "dofs": self.dofs,
            "n_dirichlet": self.n_dirichlet,
            "nullspace": self.nullspace,
            "nnz": self.nnz,
            "solver": self.solve.summary(),
            "converged": self.converged,
            "interrupted": self.interrupted is not None,
            "errors": self.errors,
            "error_estimate": self.error_estimate,
            "effectivity": self.effectivity,
            "adaptive": self.adaptive,
            "timings": dict(self.timings),
            "expressions": {k: f.source for k, f in self.case.functions.items()},
            "files": list(self.files),
            "backend": self.case.solver.backend,
            "parallel": self.parallel,
        }

    def summary_lines(self) -> list[str]:
        """Short human summary (what ``femkit solve`` prints)."""
        s = self.solve
        q = self.quality
        lines = [
            f"case      {self.case.name} (problem {self.case.problem})",
            f"mesh      {self.mesh.n_points} points, {self.mesh.n_triangles} triangles, "
            f"h_max {q.get('h_max', float('nan')):.3g}, min angle {q.get('min_angle', float('nan')):.1f} deg",
            f"system    {self.dofs} dofs ({self.n_dirichlet} Dirichlet nodes eliminated), nnz {self.nnz}",
        ]
        if self.nullspace is not None:
            ns = self.nullspace
            lines[-1] = (f"system    {self.dofs} dofs, pure Neumann: constant fixed by {ns['mode']} "
                         f"({ns['how']}), nnz {self.nnz}")
            lines.append(f"data      int f dx {ns['source_integral']:.4e} + int h ds "
                         f"{ns['flux_integral']:.4e}: relative imbalance "
                         f"{ns['relative_imbalance']:.2e} (<= {ns['rtol']:g}) removed")
        pc = f" + {s.preconditioner}" if s.preconditioner not in ("none", "", None) else ""
        status = "converged" if s.converged else f"NOT converged ({s.reason})"
        mg = getattr(s, "info", None) or {}
        if mg.get("stopped_by") == "discretisation-error estimate":
            # fmg stops on the error, not on the residual: a residual tolerance beside a
            # relative residual of 1e-3 would read as a contradiction
            lines.append(f"solver    {s.method}{pc}: {status} to the discretisation error "
                         f"(algebraic error {mg['algebraic_error_estimate']:.2e} <= "
                         f"{mg['fraction']:g} x estimated discretisation error "
                         f"{mg['discretisation_error_estimate']:.2e}, energy norm), "
                         f"{s.iterations} V-cycles on the finest level; true residual "
                         f"{s.true_residual:.3e} (relative {s.relative_residual:.3e}: not the "
                         f"criterion)")
        else:
            lines.append(f"solver    {s.method}{pc}: {status}, {s.iterations} iterations, "
                         f"true residual {s.true_residual:.3e} (relative {s.relative_residual:.3e}, "
                         f"tolerance {s.tolerance:.3e})")
        if self.errors is not None:
            lines.append("errors    " + ", ".join(f"{k} {v:.4e}" for k, v in self.errors.items()
                                                  if v is not None))
        if self.error_estimate is not None:
            e = self.error_estimate
            eff = f", effectivity {self.effectivity:.3f}" if self.effectivity is not None else ""
            lines.append(f"estimate  energy-norm error ~ {e['energy']:.4e} ({e['estimator']} "
                         f"estimator{eff})")
        if self.adaptive is not None:
            a = self.adaptive
            met = ("target met" if a["target_met"] else
                   f"target NOT met: stopped by {a['stop_reason']}" if a.get("target") is not None
                   else f"stopped by {a['stop_reason']}")
            lines.append(f"adaptive  {len(a['levels'])} levels, theta {a['theta']:g}, "
                         f"{a['levels'][0]['dofs']} -> {a['levels'][-1]['dofs']} dofs; {met}")
        lines.append("time      " + ", ".join(f"{k} {v:.3f} s" for k, v in self.timings.items()))
        if self.output_dir is not None:
            lines.append(f"output    {self.output_dir} ({', '.join(self.files)})")
        return lines


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
    from ...timing import StageTimer

    stage = StageTimer()
    target = None
    if write:  # a bad output location is bad input: refuse it before any work is done
        from .output import output_location

        target = output_location(output_dir or case.data["output"]["dir"])
    stop = case.run_options.get("stop")
    plan = case.run_options.get("plan")
    report = Progress.planned([(st.name, st.seconds) for st in plan.stages] if plan else [],
                              case.name, quiet=quiet)

    def check_stop(where: str) -> None:  # a signal during a stage stops after it
        report.done(where, *(("refine",) if where == "mesh" else ()))  # mesh includes refine
        if stop:
            raise Interrupted(stop, stage=where)

    with stage("mesh"):
        mesh, hierarchy = build_mesh_levels(case)
    check_stop("mesh")
    grad = exact_gradient(case)
    run = est = None
    if case.data.get("adaptive"):
        from .estimate import solve_adaptive

        with stage("adaptive"):
            run = solve_adaptive(case, mesh)
        mesh, problem, u, res, est = run.mesh, run.problem, run.u, run.result, run.estimate
        system = problem.system
    else:
        problem = poisson_problem(case, mesh)
        with stage("assembly"):
            K, F = problem.assemble_matrices()
        check_stop("assembly")
        with stage("boundary"):
            system = problem.reduce(K, F, case.solver.method)
        check_stop("boundary")
        with stage("assembly"):  # the coarser levels' systems (fmg only): added to the stage
            mg = multigrid_inputs(case, hierarchy, system)
        with stage("solve"):
            res = _solve(case, system, stop, **mg)
            u = system.expand(res.x)
        report.done("solve")
    q = quality(mesh)
    errors = None
    if "exact.u" in case.functions:
        with stage("errors"):
            errors = compute_errors(case, problem, u)
    from .estimate import adaptive_facts, estimate_facts

    with stage("estimate"):
        estimate, effectivity, est = estimate_facts(case, problem, u, grad, est)
    result = CaseResult(case=case, mesh=mesh, u=u, kappa=problem.kappa, solve=res, errors=errors,
                        timings=stage.times, quality=q, dofs=int(system.A.shape[0]),
                        n_dirichlet=len(system.fixed) if not is_pure_neumann(case) else 0,
                        nnz=int(system.A.nnz), nullspace=_nullspace_facts(system),
                        error_estimate=estimate, effectivity=effectivity, indicators=est.indicators,
                        adaptive=adaptive_facts(run) if run is not None else None,
                        interrupted=stop.name if res.reason == "interrupted" else None)
    if write:
        from .output import write_outputs

        write_outputs(result, target)
    if not quiet:
        out = echo or print
        for line in result.summary_lines():
            out(line)
    return result


def _solve(case: Case, system, stop, **mg):
    """Solve the reduced system (``mg``: multigrid inputs); a stop request during an iterative
    solve ends it with the last iterate as a not-converged result (``reason: interrupted``)
    that is written like any other."""
    if stop is None:
        return case.solver.solve(system.A, system.b, **mg)
    from ...interrupt import stopping_callback
    from ...solvers.result import SolveResult

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


def _nullspace_facts(system) -> dict | None:
    """result.json's ``nullspace``: mode, how the constant was fixed, the compatibility check."""
    mode = getattr(system, "mode", None)
    if mode is None:
        return None
    if getattr(system, "bordered", False):
        how = "bordered matrix [[K, w], [w^T, 0]], LU"
    else:
        how = f"node {int(system.fixed[0])} pinned" + (", shifted to mean zero" if mode == "mean_zero" else "")
    return {"mode": mode, "how": how, **system.compatibility}
