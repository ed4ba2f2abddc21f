"""The stages of the Poisson pipeline: a case translated into meshes, a
:class:`femkit.fem.PoissonProblem`, its errors, and the :class:`CaseResult` of a run.

Shared by the serial run (:mod:`.run`), the distributed one (:mod:`.distributed`), the adaptive
loop (:mod:`.estimate`), ``femkit check`` and every study kind.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import CaseFileError, ExpressionError, InputError
from ..load import Case
from ..name_checks import with_prefix
from ..result import RunResult

__all__ = ["VARIABLES", "check_dimension", "build_mesh", "build_mesh_levels", "multigrid_inputs",
           "multigrid_overrides", "on_free_nodes", "level_system",
           "element_kappa", "constant_kappa", "poisson_problem", "is_pure_neumann", "exact_gradient",
           "compute_errors", "CaseResult", "nullspace_facts"]

# ----------------------------------------------------------------------------- stages

#: The variables of a Poisson case's expressions; ``z`` exists on tetrahedral meshes only
#: (an expression that does not name it is called with ``(x, y)`` on a triangle mesh).
VARIABLES = ("x", "y", "z")


def check_dimension(case: Case, dim: int, where: str) -> None:
    """Refuse, in one line naming the option, what does not exist in ``dim`` dimensions: ``z``
    in an expression on a triangle mesh, an ``exact.grad`` with another number of components,
    a load quadrature rule of the other cell shape. ``where`` names the mesh (for the message).

    Raises
    ------
    CaseFileError
    """
    from ...fem.quadrature import get_rule
    from ...errors import UnknownNameError
    from ...mesh.mesh import CELLS_NAME

    if dim == 2:
        for key, fn in case.functions.items():
            if "z" in fn.used:
                raise CaseFileError(f"{key}: uses z, which exists on 3D meshes only; {where} is "
                                    f"a 2D mesh (triangles)")
    grad = (case.data.get("exact") or {}).get("grad")
    if grad and len(grad) != dim:
        names = ", ".join(f"du/d{c}" for c in VARIABLES[:dim])
        raise CaseFileError(f"exact.grad: {len(grad)} components, but {where} is a {dim}D mesh "
                            f"({CELLS_NAME[dim]}): give {dim} ({names})")
    rule = case.data["quadrature"]["load"]
    try:
        get_rule(rule, dim=dim)
    except UnknownNameError as exc:
        raise CaseFileError(f"quadrature.load: {rule!r} is not a rule on {CELLS_NAME[dim]}, and "
                            f"{where} is a {dim}D mesh; {str(exc).split('; ', 1)[-1]}") from None

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
    from ...mesh.validate import drop_unreferenced
    from ..cost import check_mesh_fits

    spec = case.spec.mesh
    where = f"mesh.file {spec.file}" if spec.file is not None else f"mesh.geometry {spec.geometry}"
    force = case.options.force  # --force also passes the memory guard
    try:
        if spec.file is not None:
            # a file's unused nodes (gmsh's circle centres ...) are dropped with a printed note
            mesh, note = drop_unreferenced(read_mesh(spec.file, compact=False))
            notes = case.notes
            if note and f"mesh.file: {note}" not in notes:
                notes.append(f"mesh.file: {note}")
        else:
            hv = spec.h if h is None else h
            check_mesh_fits(geometry=spec.geometry, h=hv, params=dict(spec.params), force=force)
            mesh = generate(spec.geometry, hv, **spec.params)
        mesh = validate(mesh)
    except InputError as exc:  # a message naming the file already says where
        named = spec.file is not None and str(spec.file) in str(exc)
        raise with_prefix(exc, "mesh.file" if named else where) from None
    if spec.file is not None:
        check_dimension(case, mesh.dim, where)
    hierarchy = None
    k = spec.refine
    if k:
        # before numpy allocates
        check_mesh_fits(triangles=mesh.n_cells, refine=k, dim=mesh.dim, force=force)
        # tetrahedral hierarchies always: Gauss-Seidel sweeps run in storage order, and in the
        # refinement's own numbering (coarse nodes first) the V(2,2) factor exceeds 0.2 at 6
        # levels (0.209; 0.154 renumbered: docs/methods.md)
        big = mesh.n_cells * (2 ** mesh.dim) ** k >= RENUMBER_MIN_TRIANGLES or mesh.dim == 3
        if big or case.solver.needs_hierarchy:
            levels = MeshHierarchy.from_refinement(mesh, k, renumber="rcm" if big else "none")
            mesh = levels.finest
            hierarchy = levels if case.solver.needs_hierarchy else None
        else:
            mesh = refine(mesh, k)
    bnd = case.spec.boundary
    for kind in ("dirichlet", "neumann"):
        for i, bc in enumerate(getattr(bnd, kind)):
            tags = [t for t in bc["tags"] if not _is_whole_boundary(mesh, t)]
            if tags:
                try:
                    check_tags(mesh, tags, kind="boundary")
                except InputError as exc:
                    raise with_prefix(exc, f"boundary.{kind}[{i}].tags") from None
    coef = case.spec.coefficient
    if isinstance(coef, dict):
        try:
            check_tags(mesh, list(coef["regions"]), kind="cell")
        except InputError as exc:
            raise with_prefix(exc, "coefficient.regions") from None
    return mesh, hierarchy


def multigrid_inputs(case: Case, hierarchy, system) -> dict:
    """What geometric multigrid needs at solve time, as :meth:`SolverSpec.solve` overrides:
    the hierarchy and the free nodes; for ``fmg`` with Dirichlet conditions also the coarser
    levels' own right-hand sides (:func:`level_system`: the load alone when the Dirichlet data are
    zero). Empty for every other solver. (fmg's ``dirichlet=`` option builds the coarser problems
    from the finest level's Dirichlet values alone; the pipeline keeps the assembled loads, whose
    results it has always given.) fmg is told not to check the symmetry of ``system.A``, the
    pipeline's own assembly, symmetric by construction."""
    spec = case.solver
    if not spec.needs_hierarchy:
        return {}
    levels = None
    if spec.method == "fmg" and not is_pure_neumann(case):
        levels = [level_system(case, m, spec.method) for m in hierarchy.meshes[:-1]]
    if case.spec.element != "P1":  # P2: a p-level above the P1 hierarchy (P1 -> P2 on one mesh)
        if levels is not None:
            levels.append(level_system(case, hierarchy.finest, spec.method, element="P1"))
        hierarchy = hierarchy.with_quadratic_level()
    # the solve reads the coarser levels' sizes and transfers only: their meshes are released
    # with the caller's hierarchy (run_poisson drops it before the solve)
    out = multigrid_overrides(spec, hierarchy.without_coarse_meshes(), system.free, levels)
    if spec.method == "fmg":
        # the P1 stiffness is symmetric bit for bit by construction (entry (i, j) and (j, i) sum
        # the same products in the same element order; elimination drops rows and columns
        # alike): fmg's symmetry check of the finest matrix would only confirm it
        out["options"]["check_symmetry"] = False
        if case.spec.element != "P1":
            # fmg's discretisation-error estimate compares consecutive levels' solutions: across
            # the p-level that is P1's error (O(h)), not P2's (O(h^2)), so the estimate test would
            # stop on the P2 level far above its discretisation error; the residual rule stops it
            out["options"]["target"] = "residual"
    return out


def on_free_nodes(overrides: dict) -> dict:
    """:func:`multigrid_inputs`' overrides with their hierarchy replaced by its transfers on the
    free nodes (:meth:`~femkit.mesh.MeshHierarchy.on_free_nodes`; the fixed-column parts for
    ``fmg`` with level systems or Dirichlet data, which reads them): the same matrices the
    solver would restrict, so the same numbers. Called at the start of the solve, whose set-up
    has always built them, on overrides that hold the only reference to the hierarchy (the run
    drops its own), it releases the full prolongations before the solve (61 MiB at 1.9M fine
    nodes, alive beside the restricted ones at the solve's peak until then). Updated in place
    and returned."""
    for key in ("options", "preconditioner_options"):
        mg = overrides.get(key)
        if mg and mg.get("hierarchy") is not None:
            fixed = mg.get("levels") is not None or mg.get("dirichlet") is not None
            mg["hierarchy"] = mg["hierarchy"].on_free_nodes(mg["free"], fixed_parts=fixed)
    return overrides


def level_system(case: Case, mesh, method: str, *, element: str = "P1"):
    """A coarser level's system for ``fmg``, which takes its right-hand side and Dirichlet
    values (its operator is the Galerkin product of the finer one's, built by the solver).

    With homogeneous Dirichlet data the lifting ``K[free, fixed] g`` is zero, so ``b`` is
    the load on the free nodes and no stiffness matrix is assembled (``A`` is None): the same
    ``b``, bit for bit, as the full assembly gives. Otherwise the level is assembled whole.
    """
    from ...fem import assemble_load
    from ...fem.dirichlet import DirichletSystem

    problem = poisson_problem(case, mesh, scalar_kappa=True, element=element)  # its load alone
    fixed, values = problem.dirichlet_data()
    if np.any(values != 0):
        return problem.assemble(method)
    F = assemble_load(mesh, problem.f, rule=problem.load_rule) + problem.neumann_vector()
    is_fixed = np.zeros(mesh.n_points, dtype=bool)
    is_fixed[fixed] = True
    return DirichletSystem(A=None, b=F[~is_fixed], free=np.flatnonzero(~is_fixed), fixed=fixed,
                           values=values, n=mesh.n_points)


def multigrid_overrides(spec, hierarchy, free, levels=None, *, dirichlet=None) -> dict:
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
    if dirichlet is not None:
        mg["dirichlet"] = dirichlet
    return {"options": mg}


def _is_whole_boundary(mesh, tag) -> bool:
    """``boundary`` names the whole (topological) boundary of a mesh without such a group."""
    return tag == "boundary" and "boundary" not in mesh.tag_names


def element_kappa(case: Case, mesh) -> np.ndarray:
    """Per-triangle coefficient values (constant, expression at barycentres, or region table)."""
    from ...fem.coefficients import element_coefficient

    coef = case.spec.coefficient
    if isinstance(coef, dict):
        from ...mesh import check_tags

        values = np.full(mesh.n_cells, float(coef.get("default", np.nan)))
        for name, value in coef["regions"].items():
            (tag,) = check_tags(mesh, [name], kind="cell")
            values[mesh.cell_tags == tag] = float(value)
        missing = np.flatnonzero(np.isnan(values))
        if missing.size:
            tags = sorted(set(mesh.cell_tags[missing].tolist()))
            raise CaseFileError(
                f"coefficient.regions: {missing.size} {mesh.cell_name}s (cell tags {tags}) are in no "
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


def constant_kappa(case: Case) -> float | None:
    """The coefficient as one number when the case gives a plain positive finite number, else
    None. Assembly, the energy error and the residual estimator take it as is: the same numbers
    as an array of that value per cell, without the array."""
    coef = case.spec.coefficient
    if isinstance(coef, bool) or not isinstance(coef, (int, float)):
        return None
    val = float(coef)
    return val if np.isfinite(val) and val > 0 else None


def poisson_problem(case: Case, mesh, *, load_rule: str | None = None,
                    scalar_kappa: bool = False, element: str | None = None):
    """The case on ``mesh`` as a :class:`femkit.fem.PoissonProblem` (the one translation).

    Dirichlet entries naming the whole boundary together with other tags cover both (a later
    entry wins on shared nodes); a Neumann entry naming the whole boundary takes each boundary
    edge once. Pure Neumann with ``nullspace: pin`` pins node 0 to the exact solution's value
    there when ``exact`` is given, else to 0. ``scalar_kappa``: a constant coefficient stays one
    number (:func:`constant_kappa`) instead of one value per cell (:func:`element_kappa`).
    ``element``: instead of the case's (the P1 levels below a P2 problem in multigrid).
    """
    from ...fem import PoissonProblem

    bnd = case.spec.boundary
    dirichlet = []
    for i, bc in enumerate(bnd.dirichlet):
        g = case.functions[f"boundary.dirichlet[{i}].value"]
        named = [t for t in bc["tags"] if not _is_whole_boundary(mesh, t)]
        if len(named) < len(bc["tags"]):
            dirichlet.append((None, g))
        if named:
            dirichlet.append((named, g))
    neumann = [(_tags(mesh, bc["tags"]), case.functions[f"boundary.neumann[{i}].flux"])
               for i, bc in enumerate(bnd.neumann)]
    extra = {}
    if not dirichlet:
        extra = dict(nullspace=bnd.nullspace, compatibility_rtol=bnd.compatibility_rtol)
        if bnd.nullspace == "pin" and "exact.u" in case.functions:
            u0 = case.functions["exact.u"](*mesh.points[:1].T)
            extra["pin_value"] = float(np.asarray(u0).ravel()[0])
    kappa = constant_kappa(case) if scalar_kappa else None
    return PoissonProblem(mesh, element_kappa(case, mesh) if kappa is None else kappa,
                          case.functions["source"],
                          dirichlet=dirichlet, neumann=neumann,
                          load_rule=load_rule or case.spec.load_rule,
                          element=element or case.spec.element,
                          **extra)


def is_pure_neumann(case: Case) -> bool:
    """True when the case has no Dirichlet condition (``u`` fixed only up to a constant)."""
    return case.spec.boundary.pure_neumann


def exact_gradient(case: Case):
    """``grad u`` of ``exact`` as one callable ``(x, y) -> (gx, gy)`` (``(x, y, z) -> (gx, gy,
    gz)`` on tetrahedra), or None."""
    if "exact.grad[0]" not in case.functions:
        return None
    from ..expressions import Gradient

    return Gradient([case.functions[f"exact.grad[{i}]"] for i in range(len(VARIABLES))
                     if f"exact.grad[{i}]" in case.functions])


def compute_errors(case: Case, problem, u: np.ndarray, *, order: int = 5) -> dict | None:
    """Error norms against ``exact`` (None when the case gives no exact solution); pure
    Neumann: modulo the constant (:meth:`femkit.fem.PoissonProblem.errors`)."""
    if "exact.u" not in case.functions:
        return None
    return problem.errors(u, case.functions["exact.u"], exact_gradient(case), order=order)


# ----------------------------------------------------------------------------- result

#: The mesh quality numbers result.json reports, per dimension (:func:`femkit.mesh.quality`).
_QUALITY_KEYS = {2: ("n_points", "n_triangles", "h_max", "h_min", "h_mean", "min_angle",
                     "max_aspect_ratio", "area"),
                 3: ("n_points", "n_tetrahedra", "h_max", "h_min", "h_mean", "min_dihedral",
                     "max_dihedral", "min_radius_ratio", "volume")}

@dataclass
class CaseResult(RunResult):
    """Everything a Poisson run produced (arrays in memory, facts in :meth:`to_dict`): the
    Poisson kind's :class:`~femkit.case.result.RunResult`."""

    case: Case
    mesh: Any
    u: np.ndarray
    kappa: np.ndarray | float  # one number for a constant coefficient
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
    clock: Any = None  # a femkit.timing.WallClock: result.json's "wall" (start-up, stages, other)

    @property
    def converged(self) -> bool:
        return bool(self.solve.converged)

    def facts(self) -> dict:
        """The Poisson keys of ``result.json`` (documented in docs/case-files.md)."""
        spec = self.case.spec.mesh
        from ...mesh.mesh import CELLS_NAME

        mesh_info = {"dim": self.mesh.dim}
        mesh_info.update({k: self.quality.get(k) for k in _QUALITY_KEYS[self.mesh.dim]})
        mesh_info["n_points"] = self.mesh.n_points
        mesh_info[f"n_{CELLS_NAME[self.mesh.dim]}"] = self.mesh.n_cells
        mesh_info["source"] = spec.source()
        mesh_info["refine"] = spec.refine
        mesh_info["element"] = self.case.spec.element
        return {
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
            "wall": self.clock.facts(self.timings) if self.clock is not None else None,
            "expressions": {k: f.source for k, f in self.case.functions.items()},
            "files": list(self.files),
            "backend": self.case.solver.backend,
            "parallel": self.parallel,
        }

    def summary_lines(self) -> list[str]:
        """Short human summary (what ``femkit solve`` prints)."""
        s = self.solve
        q = self.quality
        from ...mesh.mesh import CELLS_NAME

        nan = float("nan")
        angle = (f"min angle {q.get('min_angle', nan):.1f} deg" if self.mesh.dim == 2 else
                 f"min dihedral angle {q.get('min_dihedral', nan):.1f} deg")
        lines = [
            f"case      {self.case.name} (problem {self.case.problem})",
            f"mesh      {self.mesh.n_points} points, {self.mesh.n_cells} "
            f"{CELLS_NAME[self.mesh.dim]}, h_max {q.get('h_max', nan):.3g}, {angle}",
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
            worst = min((lv.get("min_angle") or nan) for lv in a["levels"])
            kind = "dihedral angle" if self.mesh.dim == 3 else "angle"
            lines.append(f"adaptive  {len(a['levels'])} levels, theta {a['theta']:g}, "
                         f"{a['levels'][0]['dofs']} -> {a['levels'][-1]['dofs']} dofs; {met}; "
                         f"smallest {kind} on any level {worst:.1f} deg")
        lines.append(self.timings_line())
        if self.output_dir is not None:
            lines.append(self.output_line(names=True))
        return lines



def nullspace_facts(system) -> dict | None:
    """result.json's ``nullspace``: mode, how the constant was fixed, the compatibility check."""
    mode = getattr(system, "mode", None)
    if mode is None:
        return None
    if getattr(system, "bordered", False):
        how = "bordered matrix [[K, w], [w^T, 0]], LU"
    else:
        how = f"node {int(system.fixed[0])} pinned" + (", shifted to mean zero" if mode == "mean_zero" else "")
    return {"mode": mode, "how": how, **system.compatibility}
