"""Run a ``problem: poisson`` case end to end: mesh, assembly, boundary, solve, errors, output.

Each stage is a small public function, so a Python user can reuse or replace any one of
them (their own mesh, coefficient, solver) and still get the same outputs::

    case = femkit.load_case("cases/poisson_unit_square.yaml", mesh={"h": 0.1})
    result = case.run(write=False)          # or step by step:
    mesh = build_mesh(case)
    K, F, kappa = assemble_system(case, mesh)
    system = dirichlet_system(case, mesh, K, F)
    res = solve_system(case, system.A, system.b)

Nothing is written before the mesh is built and checked against every tag the case names,
so bad input leaves no output directory behind; the output directory itself appears
atomically (see :func:`femkit.io.atomic.atomic_directory`).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..errors import CaseFileError, ExpressionError, InputError
from .names import check_geometry_spec, lookup, resolve_file, with_prefix
from .expressions import compile_expression
from .load import Case

__all__ = ["prepare_poisson", "run_poisson", "build_mesh", "element_kappa", "assemble_system",
           "dirichlet_data", "dirichlet_system", "solve_system", "compute_errors", "CaseResult"]


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
    from .specs import solver_spec

    d["solver"] = solver_spec(d["solver"], "solver", default_method="pcg").to_dict()

    from ..fem.quadrature import QUADRATURE

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
    from ..fem.poisson import COMPATIBILITY_RTOL

    if bnd.get("dirichlet"):
        for key in ("nullspace", "compatibility_rtol"):
            if key in bnd:
                raise CaseFileError(f"boundary.{key}: only for pure-Neumann problems (no "
                                    "boundary.dirichlet); remove it or the Dirichlet conditions")
        return
    bnd.setdefault("nullspace", "mean_zero")
    bnd.setdefault("compatibility_rtol", COMPATIBILITY_RTOL)


def is_pure_neumann(case: Case) -> bool:
    """True when the case has no Dirichlet condition (``u`` fixed only up to a constant)."""
    return not case.data["boundary"].get("dirichlet")


# ----------------------------------------------------------------------------- stages

def build_mesh(case: Case):
    """Generate or read the mesh, refine, validate, and check every tag the case names."""
    from ..mesh import check_tags, generate, read_mesh, refine, validate

    spec = case.data["mesh"]
    where = f"mesh.file {spec['file']}" if "file" in spec else f"mesh.geometry {spec['geometry']}"
    try:
        if "file" in spec:
            mesh = read_mesh(spec["file"])
        else:
            mesh = generate(spec["geometry"], spec["h"], **(spec.get("params") or {}))
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
    from ..fem.coefficients import element_coefficient

    coef = case.data["coefficient"]
    if isinstance(coef, dict):
        from ..mesh import check_tags

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


def assemble_system(case: Case, mesh):
    """Stiffness matrix, load vector (with Neumann fluxes) and per-element kappa."""
    from ..fem import assemble_load, assemble_stiffness

    kappa = element_kappa(case, mesh)
    K = assemble_stiffness(mesh, kappa)
    F = assemble_load(mesh, case.functions["source"], rule=case.data["quadrature"]["load"])
    return K, F + neumann_load(case, mesh), kappa


def neumann_load(case: Case, mesh) -> np.ndarray:
    """The load of every ``boundary.neumann`` flux, ``int h N_i ds`` (zeros without any)."""
    from ..fem import assemble_neumann

    F = np.zeros(mesh.n_points)
    for i, bc in enumerate(case.data["boundary"].get("neumann", [])):
        named = [t for t in bc["tags"] if not _is_whole_boundary(mesh, t)]
        # the whole boundary (tags=None) covers every named edge: take each edge once
        tags = named if len(named) == len(bc["tags"]) else None
        F += assemble_neumann(mesh, tags, case.functions[f"boundary.neumann[{i}].flux"])
    return F


def dirichlet_data(case: Case, mesh) -> tuple[np.ndarray, np.ndarray]:
    """Dirichlet nodes and values; a later entry wins on shared nodes (e.g. corners).

    Empty arrays for a pure-Neumann case (see :func:`nullspace_system`).
    """
    from ..mesh import boundary_nodes

    all_nodes, all_vals = [np.zeros(0, dtype=np.int64)], [np.zeros(0)]  # none: pure Neumann
    for i, bc in enumerate(case.data["boundary"].get("dirichlet", [])):
        g = case.functions[f"boundary.dirichlet[{i}].value"]
        parts = []
        named = [t for t in bc["tags"] if not _is_whole_boundary(mesh, t)]
        if named:
            parts.append(boundary_nodes(mesh, named))
        if len(named) < len(bc["tags"]):
            parts.append(boundary_nodes(mesh, None))
        nodes = np.unique(np.concatenate(parts))
        p = mesh.points[nodes]
        all_nodes.append(nodes)
        all_vals.append(g(p[:, 0], p[:, 1]))
    nodes = np.concatenate(all_nodes)
    vals = np.concatenate(all_vals)
    # keep the last occurrence of each node
    rev_unique, rev_idx = np.unique(nodes[::-1], return_index=True)
    return rev_unique, vals[::-1][rev_idx]


def dirichlet_system(case: Case, mesh, K, F):
    """Eliminate the Dirichlet nodes: an SPD reduced system (``.A``, ``.b``, ``.expand``).

    Pure Neumann (no ``boundary.dirichlet``): check the compatibility of the data and fix
    the constant as ``boundary.nullspace`` says (a
    :class:`~femkit.fem.poisson.NullspaceSystem` with the same interface).
    """
    if is_pure_neumann(case):
        return nullspace_system(case, mesh, K, F)
    from ..fem import apply_dirichlet

    nodes, values = dirichlet_data(case, mesh)
    return apply_dirichlet(K, F, nodes, values)


def nullspace_system(case: Case, mesh, K, F):
    """The pure-Neumann system: compatibility checked, constant fixed (``boundary.nullspace``).

    ``pin`` pins node 0 to the exact solution's value there when ``exact`` is given, else to 0.
    """
    from ..fem.poisson import check_compatibility, node_weights, pure_neumann_system

    bnd = case.data["boundary"]
    w = node_weights(mesh)
    F_flux = neumann_load(case, mesh)
    F, info = check_compatibility(F - F_flux, F_flux, weights=w, rtol=bnd["compatibility_rtol"])
    pin_value = 0.0
    if bnd["nullspace"] == "pin" and "exact.u" in case.functions:
        x0, y0 = mesh.points[0]
        pin_value = float(np.asarray(case.functions["exact.u"](np.array([x0]), np.array([y0])))[0])
    return pure_neumann_system(K, F, mode=bnd["nullspace"], weights=w,
                               method=case.data["solver"]["method"], pin_node=0,
                               pin_value=pin_value, compatibility=info)


def solve_system(case: Case, A, b, x0=None, callback=None):
    """Solve with the case's solver settings through :func:`femkit.solvers.solve`."""
    from .specs import SolverSpec

    return SolverSpec(**case.data["solver"]).solve(A, b, x0, callback=callback)


def compute_errors(case: Case, mesh, u: np.ndarray) -> dict | None:
    """Error norms against ``exact`` (None when the case gives no exact solution).

    Pure Neumann: modulo the constant, i.e. of ``u - c`` with ``c`` the mean difference
    ``int (u_h - u) dx / |Omega|`` (:func:`femkit.fem.poisson.mean_shift`).
    """
    if "exact.u" not in case.functions:
        return None
    from ..fem import error_norms

    grad = None
    if "exact.grad[0]" in case.functions:
        gx, gy = case.functions["exact.grad[0]"], case.functions["exact.grad[1]"]

        def grad(x, y):
            return gx(x, y), gy(x, y)

    exact = case.functions["exact.u"]
    if is_pure_neumann(case):  # u is defined up to a constant: compare u - c with int(u - c - exact) = 0
        from ..fem.poisson import mean_shift

        u = u - mean_shift(mesh, u, exact)
    errs = error_norms(mesh, u, exact, grad)
    return {k: (None if v is None else float(v)) for k, v in errs.items()}


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
        from .._version import __version__

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
    from ..mesh import quality

    from ..timing import StageTimer

    stage = StageTimer()
    target = None
    if write:  # a bad output location is bad input: refuse it before any work is done
        target = output_location(output_dir or case.data["output"]["dir"])
    with stage("mesh"):
        mesh = build_mesh(case)
        q = quality(mesh)
    with stage("assembly"):
        K, F, kappa = assemble_system(case, mesh)
    with stage("boundary"):
        system = dirichlet_system(case, mesh, K, F)
    with stage("solve"):
        res = solve_system(case, system.A, system.b)
        u = system.expand(res.x)
    errors = None
    if "exact.u" in case.functions:
        with stage("errors"):
            errors = compute_errors(case, mesh, u)
    result = CaseResult(case=case, mesh=mesh, u=u, kappa=kappa, solve=res, errors=errors,
                        timings=stage.times, quality=q, dofs=int(system.A.shape[0]),
                        n_dirichlet=len(system.fixed) if not is_pure_neumann(case) else 0,
                        nnz=int(system.A.nnz), nullspace=_nullspace_facts(system))
    if write:
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


#: A directory holding one of these is an earlier run that a new run may replace.
PREVIOUS_RUN = ("result.json",)


def output_location(directory: str | os.PathLike) -> Path:
    """The resolved output directory, checked before the run (:func:`check_output_dir`).

    Raises
    ------
    InputError
        (prefixed ``output.dir``) ``directory`` is a file, lies below a file, or is a
        non-empty directory that is not an earlier run (no ``result.json``): replacing it
        would delete the user's files.
    """
    from ..io.atomic import check_output_dir

    try:
        return check_output_dir(directory, PREVIOUS_RUN)
    except InputError as exc:
        raise with_prefix(exc, "output.dir") from None


def write_outputs(result: CaseResult, directory: str | os.PathLike) -> Path:
    """Write result.json and the requested solution files into ``directory`` (atomically).

    ``directory`` is replaced as a whole, so it must be new, empty or an earlier run
    (:func:`output_location`).
    """
    from ..io.atomic import atomic_directory
    from ..io.results import write_json, write_plot, write_solution

    opts = result.case.data["output"]
    final = output_location(directory)
    result.output_dir = final
    t0 = time.perf_counter()
    with atomic_directory(final, PREVIOUS_RUN) as tmp:
        if opts["vtu"]:
            write_solution(tmp / "solution.vtu", result.mesh, result.u, result.kappa)
        if opts["xdmf"]:
            write_solution(tmp / "solution.xdmf", result.mesh, result.u, result.kappa)
        if opts["plot"]:
            title = (f"{result.case.name}: {result.mesh.n_triangles} triangles, "
                     f"h_max = {result.quality.get('h_max', float('nan')):.3g}")
            write_plot(tmp / "solution.png", result.mesh, result.u, title)
        result.files = sorted({p.name for p in tmp.iterdir()} | {"result.json"})
        result.timings["output"] = time.perf_counter() - t0  # up to result.json itself
        write_json(tmp / "result.json", result.to_dict())
    result.timings["output"] = time.perf_counter() - t0
    return final
