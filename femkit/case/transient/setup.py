"""What the time-dependent PDE kinds (``problem: heat``, ``problem: wave``) share: their schema
pieces, the load-time checks and spec, the system on the built mesh and the frames' numbers.

Both kinds solve ``c u^(k) - div(kappa grad u) = f(x, t)`` (``k = 1``: heat with ``c = rho_c``;
``k = 2``: wave with ``c = rho``) by P1 finite elements on femkit's meshes (the Poisson
geometries and mesh files, :func:`femkit.case.poisson.problem.build_mesh`), ``M`` from
:func:`femkit.fem.mass.mass_matrix` and ``K`` from the Poisson assembly
(:func:`femkit.fem.assemble_stiffness`), stepped by the schemes of
:mod:`femkit.dynamics.mol`. Expressions are those of :mod:`femkit.case.expressions` in the
variables ``x, y, z, t`` (``z`` on tetrahedra only).
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from ...errors import CaseFileError, ExpressionError, InputError
from ..frozen import freeze
from ..name_checks import check_geometry_spec, lookup, resolve_file, with_prefix

__all__ = ["VARIABLES", "TransientSpec", "TransientOutput", "transient_schema",
           "prepare_transient", "at_time", "element_values", "build_system", "system_parts",
           "check_step",
           "frame_errors", "initial_values", "plan_transient", "dof_points"]

#: Variables of the expressions of a time-dependent case (``z`` on tetrahedra only).
VARIABLES = ("x", "y", "z", "t")

_NUMBER_OR_EXPR = {"anyOf": [{"type": "number"}, {"type": "string", "minLength": 1}],
                   "x-message": "expected a number or an expression string of x, y, z, t"}
_POS = {"type": "number", "exclusiveMinimum": 0}
_TIME = {"anyOf": [{"type": "number"}, {"type": "string", "minLength": 1}],
         "x-message": "expected a positive number or a constant expression such as '1/100'"}


def _positive_field(default: float) -> dict:
    return {"anyOf": [_POS, {"type": "string", "minLength": 1},
                      {"type": "object", "additionalProperties": False, "required": ["regions"],
                       "properties": {"regions": {"type": "object", "minProperties": 1,
                                                  "additionalProperties": _POS},
                                      "default": _POS}}],
            "default": default,
            "x-message": "expected a positive number, an expression string, or "
                         "{regions: {name: value}, default: value}"}


def transient_schema(kind: str, capacity: str, integrators, extra: Mapping) -> dict:
    """The JSON schema of ``problem: <kind>`` (``capacity``: ``rho_c`` or ``rho``), the
    integrator enum from ``integrators`` (a registry), ``extra`` the kind's own keys."""
    from ..poisson.schema import POISSON_SCHEMA
    from ..specs import LIMITS_SCHEMA, SOLVER_SCHEMA

    base = POISSON_SCHEMA["properties"]
    names = {"enum": integrators.names()}
    integrator = {"anyOf": [names, {"type": "object", "additionalProperties": False,
                                    "required": ["method"],
                                    "properties": {"method": names, "options": {"type": "object"}}}],
                  "x-message": f"expected an integrator name ({', '.join(integrators.names())}) "
                               "or {method: name, options: {...}}"}
    props = {
        "problem": {"const": kind}, "name": base["name"], "description": base["description"],
        "constants": base["constants"], "mesh": base["mesh"],
        "element": {"type": "string", "minLength": 1, "default": "P1"},
        "coefficient": _positive_field(1.0), capacity: _positive_field(1.0),
        "source": {**_NUMBER_OR_EXPR, "default": 0.0},
        "boundary": {"type": "object", "additionalProperties": False, "default": {},
                     "properties": {k: base["boundary"]["properties"][k]
                                    for k in ("dirichlet", "neumann")}},
        "initial": {**_NUMBER_OR_EXPR, "default": 0.0},
        "exact": base["exact"],
        "mass": {"enum": ["consistent", "lumped"], "default": "consistent"},
        "integrator": integrator, "dt": _TIME, "t_end": _TIME,
        "quadrature": base["quadrature"],
        "solver": {**SOLVER_SCHEMA, "default": {}}, "limits": LIMITS_SCHEMA,
        "output": {"type": "object", "additionalProperties": False, "default": {},
                   "properties": {"dir": {"type": "string", "minLength": 1},
                                  "frames": {"type": "integer", "minimum": 1, "default": 20},
                                  "vtu": {"type": "boolean", "default": True},
                                  "png": {"type": "boolean", "default": True},
                                  "gif": {"type": "boolean", "default": False}}},
        **extra,
    }
    return {"$schema": "https://json-schema.org/draft/2020-12/schema",
            "title": f"femkit {kind} case", "type": "object", "additionalProperties": False,
            "required": ["problem", "mesh", "integrator", "dt", "t_end"], "properties": props}


@dataclass(frozen=True)
class TransientOutput:
    """``output:``: directory (absolute), frames kept (about), VTU series, PNG and GIF asked for."""

    dir: str
    frames: int
    vtu: bool
    png: bool
    gif: bool = False


@dataclass(frozen=True)
class TransientSpec:
    """Everything a heat or wave run needs, checked at load time.

    ``mesh`` and ``boundary`` are the Poisson kind's records (the same mesh building);
    ``coefficient`` is ``kappa`` and ``capacity`` ``rho_c`` (heat) or ``rho`` (wave), each a
    number, an expression (compiled in ``case.functions``) or ``{regions, default}``;
    ``integrator`` is ``(method, options)``; ``steps`` is ``ceil(t_end / dt)`` and ``dt`` the
    step that ends exactly on ``t_end`` (``dt_asked``: the file's); ``rtol_t`` set: adaptive
    steps (heat).
    """

    mesh: Any
    boundary: Any
    element: str
    coefficient: Any
    capacity: Any
    mass: str
    integrator: tuple
    dt: float
    dt_asked: float
    t_end: float
    steps: int
    rtol_t: float | None
    solver: Any
    output: TransientOutput
    load_rule: str = "barycentric"
    solver_default: bool = False  # no method named: the size rule (dynamics.mol.step_solver)


def _compile(case, key: str, text, *, check_finite: bool = True):
    from ..expressions import compile_case_expression

    return compile_case_expression(case, key, text, VARIABLES, check_finite=check_finite)


def _check_element(name: str, rule: str) -> str:
    """``name`` checked against :data:`femkit.elements.ELEMENTS` (one line listing the valid
    ones); a named load rule must integrate the element's products exactly."""
    from ...elements import ELEMENTS as registry, get_element
    from ...fem.quadrature import QUADRATURE, TET_QUADRATURE

    lookup(registry, name, "element")
    if name != "P1" and rule != "barycentric":
        need = get_element(name, 2).load_degree
        degree = (QUADRATURE.get(rule) if rule in QUADRATURE else TET_QUADRATURE.get(rule)).degree
        if degree < need:
            raise CaseFileError(f"quadrature.load {rule!r} (degree {degree}) is not exact for "
                                f"{name} products (degree >= {need}); leave quadrature.load out")
    return name


def prepare_transient(case, capacity: str, integrators, expressions: tuple = ()) -> TransientSpec:
    """Check a validated heat or wave file and build its :class:`TransientSpec` (the caller
    stores it in ``case.spec``); compile every expression (``expressions``: the kind's own keys
    beyond the common ones, e.g. ``initial_velocity``).

    Raises
    ------
    CaseFileError, ExpressionError, UnknownNameError
        One line naming the key: an unknown geometry, integrator or solver, a bad option,
        ``dt`` or ``t_end`` not positive and finite, ``z`` on a 2D geometry.
    """
    from ...kinds import KINDS
    from ..poisson.spec import BoundarySpec, MeshSpec
    from ..specs import limits_spec, solver_spec
    from ..timeline import time_value
    from ...dynamics.mol import get_scheme

    d = case.data
    if d.get("name"):
        case.name = d["name"]
    mesh = d["mesh"]
    if "file" in mesh:
        resolve_file(mesh, "mesh", case.base_dir)
    else:
        check_geometry_spec(mesh, "mesh")
    solver = solver_spec(d["solver"], "solver",
                         default_method=KINDS.get(case.problem, "problem").default_solver)
    if solver.backend not in ("femkit", "petsc"):
        raise CaseFileError(f"solver.backend: {solver.backend!r} is not offered for problem: "
                            f"{case.problem}; valid: femkit, petsc")
    if solver.needs_hierarchy:
        raise CaseFileError(f"solver: method {solver.method!r} needs a mesh hierarchy, which the "
                            "time-dependent kinds do not build; use direct, cholesky or pcg")
    case.options = dataclasses.replace(case.options, limits=limits_spec(d.get("limits")))
    integ = d["integrator"]
    method, options = (integ, {}) if isinstance(integ, str) else (integ["method"],
                                                                  dict(integ.get("options") or {}))
    try:
        get_scheme(integrators, method, **options)
    except InputError as exc:
        raise with_prefix(exc, "integrator") from None
    for key in ("source", "initial", *expressions):
        _compile(case, key, d[key])
    for key in ("coefficient", capacity):
        if isinstance(d[key], str):
            _compile(case, key, d[key])
    bnd = d["boundary"]
    for i, bc in enumerate(bnd.get("dirichlet") or []):
        _compile(case, f"boundary.dirichlet[{i}].value", bc["value"])
    for i, bc in enumerate(bnd.get("neumann") or []):
        _compile(case, f"boundary.neumann[{i}].flux", bc["flux"])
    if d.get("exact"):
        _compile(case, "exact.u", d["exact"]["u"])
        for i, g in enumerate(d["exact"].get("grad") or []):
            _compile(case, f"exact.grad[{i}]", g, check_finite=False)
    if "geometry" in mesh:
        from ...mesh.geometries import GEOMETRIES
        from ..poisson.problem import check_dimension

        check_dimension(case, GEOMETRIES.get(mesh["geometry"]).dim, f"mesh.geometry {mesh['geometry']!r}")
    dt, t_end = time_value(case, "dt"), time_value(case, "t_end")
    steps = max(1, math.ceil(t_end / dt * (1.0 - 1e-12)))
    out = d["output"]
    out["dir"] = str((case.base_dir / out.get("dir", os.path.join("runs", case.name))).resolve())
    rtol_t = d.get("rtol_t")
    return TransientSpec(
        mesh=MeshSpec.from_mapping(freeze(mesh)),
        boundary=BoundarySpec(tuple(freeze(list(bnd.get("dirichlet") or ()))),
                              tuple(freeze(list(bnd.get("neumann") or ()))), None, None),
        element=_check_element(d["element"], d["quadrature"]["load"]),
        coefficient=freeze(d["coefficient"]),
        capacity=freeze(d[capacity]), mass=d["mass"], integrator=(method, freeze(options)),
        dt=t_end / steps, dt_asked=dt, t_end=t_end, steps=steps,
        rtol_t=None if rtol_t is None else float(rtol_t), solver=solver,
        output=TransientOutput(out["dir"], int(out["frames"]), bool(out["vtu"]), bool(out["png"]),
                               bool(out["gif"])),
        load_rule=d["quadrature"]["load"],
        solver_default=isinstance(d["solver"], dict) and "method" not in d["solver"])


# ----------------------------------------------------------------------------- the system

def at_time(fn, t: float, dim: int):
    """``fn`` (an expression of ``x, y, z, t``) at time ``t`` as a callable of the mesh's
    coordinates (``(x, y)`` on triangles, ``(x, y, z)`` on tetrahedra)."""
    if dim == 2:  # z is refused on 2D meshes at load time (check_dimension)
        return lambda x, y: fn(x, y, 0.0, t)
    return lambda x, y, z: fn(x, y, z, t)


def element_values(case, mesh, value, key: str) -> np.ndarray:
    """Per-cell values of a positive field (``coefficient``, ``rho_c``, ``rho``): a number, an
    expression at the barycentres (at ``t = 0``) or ``{regions: {name: value}, default}``.

    Raises
    ------
    CaseFileError
        Cells in no listed region without a default, or a value that is not positive.
    """
    from ...fem.coefficients import element_coefficient

    if isinstance(value, Mapping):
        from ...mesh import check_tags

        out = np.full(mesh.n_cells, float(value.get("default", np.nan)))
        try:
            for name, v in value["regions"].items():
                (tag,) = check_tags(mesh, [name], kind="cell")
                out[mesh.cell_tags == tag] = float(v)
        except InputError as exc:
            raise with_prefix(exc, f"{key}.regions") from None
        if np.isnan(out).any():
            raise CaseFileError(f"{key}.regions: {int(np.isnan(out).sum())} cells are in no listed "
                                f"region; add them or give {key}.default")
        return out
    fn = case.functions.get(key)
    try:
        return element_coefficient(mesh, at_time(fn, 0.0, mesh.dim) if fn is not None
                                   else float(value), name=key)
    except ExpressionError:
        raise
    except InputError as exc:
        raise with_prefix(exc, key) from None


def _tags(mesh, tags) -> list | None:
    """``None`` (the whole boundary, found topologically) when ``tags`` names ``boundary`` on a
    mesh without such a group (the whole boundary covers the other tags), else the tags."""
    tags = list(tags)
    return None if "boundary" in tags and "boundary" not in mesh.tag_names else tags


def dof_points(case, mesh) -> np.ndarray:
    """(n_dofs, dim) coordinates of the case's element's dofs on ``mesh`` (P1: the nodes; P2:
    the nodes, then the edge midpoints)."""
    from ...fem.dofs import dof_map

    return dof_map(mesh, case.spec.element).points(mesh)


def _dirichlet(case, mesh):
    """``(fixed dofs, [(rows of fixed, expression)] in order)``: later entries win on shared dofs."""
    from ...fem.dofs import dof_map
    from ...fem.lagrange import boundary_dofs

    dofs = dof_map(mesh, case.spec.element)
    entries = []
    owner = np.full(dofs.n_dofs, -1)
    for i, bc in enumerate(case.spec.boundary.dirichlet):
        owner[boundary_dofs(mesh, dofs, _tags(mesh, bc["tags"]))] = i
        entries.append(case.functions[f"boundary.dirichlet[{i}].value"])
    fixed = np.flatnonzero(owner >= 0)
    groups = [(np.flatnonzero(owner[fixed] == i), fn) for i, fn in enumerate(entries)]
    return fixed, groups


def build_system(case, mesh, capacity: str):
    """The :class:`femkit.dynamics.mol.LinearSystem` of the case on ``mesh``: ``M`` (consistent
    or lumped, ``capacity`` per cell), ``K`` (``kappa`` per cell), the Dirichlet nodes and the
    time-dependent load and boundary values (evaluated once when they do not use ``t``)."""
    from ...dynamics.mol import LinearSystem, step_solver, stiffness_ratio

    parts = system_parts(case, mesh, capacity)
    spec = case.spec
    if spec.solver_default:   # the size rule; the step matrix M + b K: b = dt (heat), dt^2 / 4
        M, K, fixed = parts["M"], parts["K"], parts["fixed"]
        free = np.setdiff1d(np.arange(K.shape[0]), fixed)
        b = spec.dt if capacity == "rho_c" else spec.dt ** 2 / 4.0
        parts["solver"] = step_solver(mesh.dim, free.size, parts["solver"],
                                      stiffness_ratio(M, K, free, b))
    return LinearSystem(**parts)


def system_parts(case, mesh, capacity: str, elements=None) -> dict:
    """The keyword arguments of :class:`femkit.dynamics.mol.LinearSystem` for the case on
    ``mesh`` (:func:`build_system`); ``elements``: ``M`` and ``K`` of these cells only (a
    partition's part, global shape), the load and boundary data always whole."""
    from ...fem import assemble_load, assemble_neumann, assemble_stiffness
    from ...fem.forms import assemble_matrix
    from ...fem.lagrange import element_load, element_neumann
    from ...fem.mass import mass_matrix

    spec = case.spec
    lumped = spec.mass == "lumped"
    kappa = element_values(case, mesh, spec.coefficient, "coefficient")
    density = element_values(case, mesh, spec.capacity, capacity)
    p1 = spec.element == "P1"
    K = assemble_stiffness(mesh, kappa, elements=elements) if p1 else \
        assemble_matrix(mesh, "stiffness", kappa, element=spec.element, elements=elements)
    M = mass_matrix(mesh, element=spec.element, lumped=lumped, density=density,
                    elements=elements)
    n = K.shape[0]
    fixed, groups = _dirichlet(case, mesh)
    pts = dof_points(case, mesh)[fixed].T
    dim = mesh.dim

    def boundary(t):
        g = np.empty(fixed.size)
        for rows, fn in groups:
            g[rows] = fn(*pts[:, rows], *((0.0,) if dim == 2 else ()), t)
        return g

    source = case.functions["source"]
    neumann = [(_tags(mesh, bc["tags"]), case.functions[f"boundary.neumann[{i}].flux"])
               for i, bc in enumerate(spec.boundary.neumann)]
    zero_source = source.is_constant and float(source(0.0, 0.0, 0.0, 0.0)) == 0.0
    has_load = not zero_source or bool(neumann)

    rule = None if spec.load_rule == "barycentric" else spec.load_rule  # P2: its own default

    def load(t):
        if p1:
            F = np.zeros(n) if zero_source else \
                assemble_load(mesh, at_time(source, t, dim), rule=spec.load_rule)
            for tags, h in neumann:
                F += assemble_neumann(mesh, tags, at_time(h, t, dim))
            return F
        F = np.zeros(n) if zero_source else \
            element_load(mesh, at_time(source, t, dim), spec.element, rule=rule)
        for tags, h in neumann:
            F += element_neumann(mesh, tags, at_time(h, t, dim), spec.element)
        return F

    uses_t = [fn for fn in [source, *(h for _, h in neumann)] if "t" in fn.used]
    return dict(M=M, K=K, fixed=fixed, load=load if has_load else None,
                boundary=boundary if groups else None, load_constant=not uses_t,
                boundary_constant=not any("t" in fn.used for _, fn in groups),
                lumped=lumped, solver=spec.solver)


def initial_values(case, mesh, key: str) -> np.ndarray:
    """Values at the dofs of the expression ``key`` (``initial``, ``initial_velocity``) at
    ``t = 0`` (its interpolant)."""
    return np.asarray(at_time(case.functions[key], 0.0, mesh.dim)(*dof_points(case, mesh).T),
                      dtype=np.float64)


def check_step(case, system, scheme) -> dict:
    """Refuse a step above the scheme's critical step on this mesh (explicit and conditionally
    stable schemes; ``--force`` runs it anyway); returns ``{dt_critical, lambda_max}`` (None
    for unconditionally stable schemes, which compute no eigenvalue).

    Raises
    ------
    BudgetExceededError
        ``dt > dt_crit``: one line naming the largest stable step (exit 2, nothing written).
    """
    from ...dynamics.mol import critical_step
    from ...errors import BudgetExceededError
    from ...cost.plan import round_down

    if math.isinf(scheme.stability_bound):
        return {"dt_critical": None, "lambda_max": None}
    dt_crit, lam = critical_step(scheme, system)
    spec = case.spec
    if spec.dt > dt_crit and not case.options.force:
        raise BudgetExceededError(
            f"dt: {spec.dt:g} exceeds the critical step {dt_crit:.6g} of {scheme.name} on this mesh "
            f"({spec.mass} mass, lambda_max(M^-1 K) = {lam:.6g}); the largest stable dt is "
            f"{round_down(dt_crit)} (or use an implicit integrator, or --force)",
            "dt", spec.dt, dt_crit)
    return {"dt_critical": float(dt_crit), "lambda_max": float(lam)}


#: Nodal values this large (an unstable run forced past its critical step) get no error norms:
#: their squares overflow. The frame's norms are None.
OVERFLOW = 1e100


def frame_errors(case, mesh, frames) -> dict | None:
    """L2 and H1-seminorm errors against ``exact`` at every frame time, and their maxima over
    time (None without ``exact``; None at a frame whose values reach :data:`OVERFLOW`)."""
    from ...fem import error_norms
    from ..expressions import Gradient

    exact = case.functions.get("exact.u")
    if exact is None:
        return None
    parts = [case.functions[f"exact.grad[{i}]"] for i in range(3) if f"exact.grad[{i}]" in case.functions]
    history = []
    for t, u, _ in frames:
        if not np.abs(u).max(initial=0.0) < OVERFLOW:  # an unstable run (--force): no norm
            history.append({"t": float(t), "L2": None, "H1_semi": None, "max_nodal": None})
            continue
        grad = None
        if parts:
            grad = Gradient([_Frozen(p, t, mesh.dim) for p in parts])
        if case.spec.element == "P1":
            e = error_norms(mesh, u, at_time(exact, t, mesh.dim), grad)
        else:
            from ...fem.lagrange import element_error_norms

            e = element_error_norms(mesh, u, at_time(exact, t, mesh.dim), grad,
                                    element=case.spec.element)
        history.append({"t": float(t), "L2": e["L2"], "H1_semi": e["H1_semi"],
                        "max_nodal": e["max_nodal"]})
    top = {k: max((h[k] for h in history if h[k] is not None), default=None)
           for k in ("L2", "H1_semi", "max_nodal")}
    return {"history": history, "max_over_time": top, "final": history[-1]}


class _Frozen:
    """An expression of ``x, y, z, t`` at a fixed ``t`` (a gradient component for the norms)."""

    fused = None

    def __init__(self, fn, t, dim):
        self._call = at_time(fn, t, dim)

    def __call__(self, *xyz):
        return self._call(*xyz)


# ----------------------------------------------------------------------------- the plan

#: PCG iterations of one warm-started heat step (IC(0), ``rtol`` 1e-10, the quadratic warm start
#: of :class:`femkit.dynamics.mol.system.ConstrainedOperator`): 7.8 measured at 251,809
#: unknowns, ``dt kappa / h^2 ~ 20`` (docs/benchmarks.md, ``benchmarks/bench_heat.py``); a step
#: is priced at this many iterations of the stationary solve, never more than that solve's.
STEP_ITERATIONS = 8.0


#: Seconds per entry of ``L + U`` for the pair of triangular solves of a kept SuperLU factor of a
#: heat step matrix, at the cost model's reference speed (``cost/constants.json``): measured
#: 2.5e-9 (18,727 unknowns, 1.43M entries, 25 ms) and 1.6e-9 (75,349 unknowns, 7.8M entries,
#: 114 ms) at speed x7-9, the fill law of the Poisson model within 3% of the factors' own. The
#: Poisson model's ``direct_solve_per_fill`` (3.2e-8) prices the first solve after a
#: factorisation, 13-20 times a kept factor's substitution: priced with it, implicit steps cost
#: a tenth of a factorisation each and a 410-step run came out at 102 s instead of ~6.
SUBSTITUTION_PER_FILL = 2.0e-9


def _step_prices(base, solver) -> tuple[float, float, float]:
    """``(factor, substitution, spmv)`` seconds of a plan's solver, from the Poisson plan
    ``base`` on the same mesh: the ``setup`` stage paid once (the kept factor or
    preconditioner); per step the kept factor's two triangular solves
    (:data:`SUBSTITUTION_PER_FILL` times the factor's fill ``nnz(L + U)``), or :data:`STEP_ITERATIONS`
    iterations of the stationary solve; one SpMV priced as a CG iteration on the plan's
    nonzeros, at the plan's machine speed (the ratio of its ``solve`` stage to that stage's
    unscaled price)."""
    from ...cost import load_constants
    from ...cost.poisson import solver_key
    from ...solvers.registry import priced_names

    c = load_constants()
    sec = c["seconds"]
    stages = {st.name: st.seconds for st in base.stages}
    setup, solve = stages.get("setup", 0.0), stages.get("solve", 0.0)
    nnz, unknowns = float(base.sizes["nonzeros"]), float(base.sizes["unknowns"])
    per_nnz = sec["iteration_per_nonzero"]
    if solver.method in ("direct", "cholesky"):
        fill = c["fill"]["direct_coefficient"] * unknowns ** c["fill"]["direct_exponent"]
        unscaled = sec["direct_solve_per_fill"] * fill
        substitution = SUBSTITUTION_PER_FILL * fill * (solve / unscaled if unscaled > 0 else 1.0)
    else:
        key = solver_key(*priced_names(solver.method, solver.preconditioner))
        its = max(float(base.sizes.get("iterations", 1.0)), 1.0)
        unscaled = per_nnz.get(key, per_nnz["cg"]) * nnz * its
        substitution = solve * min(1.0, STEP_ITERATIONS / its)
    speed = solve / unscaled if unscaled > 0 else 1.0
    return setup, substitution, per_nnz["cg"] * nnz * speed


def plan_transient(case, *, measure: bool = True):
    """The plan of a heat or wave case: the mesh and assembly stages of the Poisson model on
    the same mesh (:func:`femkit.case.poisson.cost.plan_poisson_case`) with the step solver the
    run will use (the size rule :func:`femkit.dynamics.mol.step_solver` when the case names
    none), its ``setup`` priced as the one factorisation (or preconditioner) kept, then
    ``steps`` steps of one SpMV and the kept factor's pair of triangular solves each, priced
    from the factor's fill (:func:`_step_prices`; an explicit scheme on a lumped mass: no
    factorisation, one SpMV per step), and the frames written."""
    from types import SimpleNamespace

    from ...cost import Plan, Stage
    from ..poisson.cost import plan_poisson_case

    spec = case.spec

    def poisson_plan(solver):
        proxy = SimpleNamespace(
            name=case.name, functions={}, solver=solver,
            spec=SimpleNamespace(mesh=spec.mesh, adaptive=None, element=spec.element,
                                 output=SimpleNamespace(vtu=False, xdmf=False, plot=False)))
        return plan_poisson_case(proxy, measure=measure)

    solver = spec.solver
    base = poisson_plan(solver)
    if spec.solver_default:   # the run's size rule (its stiffness unknown here: IC(0))
        from ...dynamics.mol import step_solver

        dim = 3 if "tetrahedra" in base.sizes else 2
        solver = step_solver(dim, int(base.sizes.get("unknowns", 0.0)), solver)
        if solver.method != spec.solver.method:
            base = poisson_plan(solver)
    keep = [st for st in base.stages if st.name in ("mesh", "quality", "assembly", "boundary")]
    factor, substitution, spmv = _step_prices(base, solver)
    peak = max(st.peak_bytes for st in base.stages)
    points = float(base.sizes.get("points", 0.0))
    steps = spec.steps
    frames = min(steps, spec.output.frames) + 1
    per_step = substitution + spmv
    if spec.mass == "lumped" and spec.integrator[0] in ("explicit_euler", "central_difference"):
        factor, per_step = 0.0, spmv   # no matrix to factorise: an SpMV and a division
    frame_bytes = 16.0 * points + 200.0
    stages = keep + [
        Stage("factor", factor, peak, 0.0,
              f"{solver.method}: one factor kept" if solver.method in ("direct", "cholesky")
              else f"{solver.method}: one preconditioner kept, warm-started solves per step"),
        Stage("steps", steps * per_step, peak + frames * 8.0 * points, 0.0,
              f"{steps:,} steps of {spec.integrator[0]}"),
        Stage("output", frames * frame_bytes / 2e7, frame_bytes, frames * frame_bytes,
              f"{frames} frames")]
    sizes = {k: v for k, v in base.sizes.items() if k != "iterations"}
    sizes.update(steps=steps, frames=frames)
    plan = Plan(case.problem, f"{base.title}, {spec.integrator[0]} x {steps:,} steps", sizes,
                stages, base.baseline_bytes,
                assumptions=base.assumptions[:2] + [
                    "each step: one SpMV and one pair of triangular solves of the kept factor "
                    f"(priced from its fill; {STEP_ITERATIONS:g} warm-started iterations with a "
                    "kept preconditioner); adaptive runs are priced at their first dt"])

    def suggest(kind: str, limit: float) -> str:
        if kind not in ("time", "steps"):
            return ""
        from ...cost.plan import round_down, round_up

        k = limit / max(plan.seconds if kind == "time" else steps, 1e-300)
        return f"dt >= {round_up(spec.dt / k)} or t_end <= {round_down(spec.t_end * k)}"

    plan.suggest = suggest
    return plan
