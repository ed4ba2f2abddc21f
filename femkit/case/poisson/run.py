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
from ..expressions import compile_expression
from ..load import Case
from ..names import check_geometry_spec, lookup, resolve_file, with_prefix

__all__ = ["prepare_poisson", "run_poisson", "build_mesh", "element_kappa", "poisson_problem",
           "compute_errors", "CaseResult"]


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
    from ..specs import solver_spec

    case.solver = solver_spec(d["solver"], "solver", default_method="pcg")
    d["solver"] = case.solver.to_dict()

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

def build_mesh(case: Case, *, h: float | None = None):
    """Generate or read the mesh, refine, validate, and check every tag the case names.

    ``h`` replaces ``mesh.h`` of a generated mesh (studies sweep it); a mesh file ignores it.
    """
    from ...mesh import check_tags, generate, read_mesh, refine, validate

    spec = case.data["mesh"]
    where = f"mesh.file {spec['file']}" if "file" in spec else f"mesh.geometry {spec['geometry']}"
    try:
        if "file" in spec:
            mesh = read_mesh(spec["file"])
        else:
            mesh = generate(spec["geometry"], spec["h"] if h is None else h, **(spec.get("params") or {}))
        mesh = validate(mesh)
    except InputError as exc:
        raise with_prefix(exc, where) from None
    if spec.get("refine"):
        mesh = refine(mesh, spec["refine"])
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
    return mesh


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
            "errors": self.errors,
            "timings": dict(self.timings),
            "expressions": {k: f.source for k, f in self.case.functions.items()},
            "files": list(self.files),
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
        lines.append(f"solver    {s.method}{pc}: {status}, {s.iterations} iterations, "
                     f"true residual {s.true_residual:.3e} (relative {s.relative_residual:.3e}, "
                     f"tolerance {s.tolerance:.3e})")
        if self.errors is not None:
            lines.append("errors    " + ", ".join(f"{k} {v:.4e}" for k, v in self.errors.items()
                                                  if v is not None))
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
    from ...mesh import quality
    from ...timing import StageTimer

    stage = StageTimer()
    target = None
    if write:  # a bad output location is bad input: refuse it before any work is done
        from .output import output_location

        target = output_location(output_dir or case.data["output"]["dir"])
    with stage("mesh"):
        mesh = build_mesh(case)
        q = quality(mesh)
    problem = poisson_problem(case, mesh)
    with stage("assembly"):
        K, F = problem.assemble_matrices()
    with stage("boundary"):
        system = problem.reduce(K, F, case.solver.method)
    with stage("solve"):
        res = case.solver.solve(system.A, system.b)
        u = system.expand(res.x)
    errors = None
    if "exact.u" in case.functions:
        with stage("errors"):
            errors = compute_errors(case, problem, u)
    result = CaseResult(case=case, mesh=mesh, u=u, kappa=problem.kappa, solve=res, errors=errors,
                        timings=stage.times, quality=q, dofs=int(system.A.shape[0]),
                        n_dirichlet=len(system.fixed) if not is_pure_neumann(case) else 0,
                        nnz=int(system.A.nnz), nullspace=_nullspace_facts(system))
    if write:
        from .output import write_outputs

        write_outputs(result, target)
    if not quiet:
        out = echo or print
        for line in result.summary_lines():
            out(line)
    return result


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
