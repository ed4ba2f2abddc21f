"""The adaptive loop solve -> estimate -> mark -> refine, with nested iteration.

Each level solves on the current mesh, estimates the energy-norm error element by element
(:mod:`femkit.fem.estimators`), marks a Dörfler set (:func:`~femkit.fem.marking.dorfler_mark`) and
refines it by newest-vertex bisection (:func:`femkit.mesh.bisect.bisect`; on tetrahedra Maubach's
conforming bisection, :class:`femkit.mesh.bisect3d.TetBisection`, from a Kuhn-type start mesh),
until the estimate
meets ``target`` or a budget (``max_dofs``, ``max_time``, ``max_levels``) is spent. The next level's
solve starts from the current solution interpolated onto the new mesh (nested iteration), so an
iterative solver needs a few iterations per level only. ``refinement="uniform"`` runs the same loop
with uniform red refinement: the baseline adaptive refinement is measured against.

The problem is supplied as a callable ``solve_on(mesh, x0) -> (problem, u, result)`` so that an
application can plug its own pipeline in; :func:`poisson_solver` builds one from Poisson data.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> pts = np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.]])
>>> m = Mesh(pts, np.array([[0, 1, 2], [0, 2, 3]]))
>>> run = adaptive_solve(poisson_solver(f=1.0, method="direct"), m, theta=0.5, max_levels=4)
>>> [lv.n_elements for lv in run.levels], run.stop_reason, run.target_met
([2, 4, 6, 8], 'max_levels', False)
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Callable, Sequence

import numpy as np

from ...errors import AdaptivityError
from ..estimators import ESTIMATORS, ErrorEstimate, problem_data
from ..marking import check_theta, dorfler_mark

REFINEMENTS = ("adaptive", "uniform")


@dataclass
class LevelRecord:
    """Facts of one level of an adaptive (or uniform) run.

    ``dofs`` unknowns of the solved system; ``estimate`` the global error estimate; ``error`` the
    true energy-norm error and ``effectivity = estimate / error`` (``None`` without an exact
    gradient); ``iterations`` of the linear solver; times in seconds: ``solve_time`` (assembly and
    solve), ``estimate_time``, ``refine_time`` (marking and refining towards the next level) and
    ``elapsed`` (wall time since the start of the run up to the end of this level's estimate, the
    true-error evaluation excluded); ``min_angle`` the smallest angle of the level's mesh in
    degrees (of a triangle in 2D, the smallest dihedral angle in 3D).
    """

    level: int
    n_elements: int
    n_nodes: int
    dofs: int
    estimate: float
    error: float | None
    effectivity: float | None
    iterations: int
    converged: bool
    solve_time: float
    estimate_time: float
    refine_time: float
    elapsed: float
    marked: int = 0
    min_angle: float | None = None

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass
class AdaptiveResult:
    """Outcome of :func:`adaptive_solve`.

    ``levels`` one :class:`LevelRecord` per solved level; ``mesh``, ``u``, ``problem``,
    ``estimate`` (an :class:`~femkit.fem.estimators.ErrorEstimate`) and ``result`` (the solver's
    SolveResult) of the last level;
    ``target_met`` whether the estimate reached ``target``; ``stop_reason`` one of
    ``target``, ``max_dofs``, ``max_time``, ``max_levels``, ``no_marked`` (zero estimate).
    """

    levels: list
    mesh: object
    u: np.ndarray
    problem: object
    estimate: ErrorEstimate
    target_met: bool
    stop_reason: str
    settings: dict = field(default_factory=dict)
    result: object = None

    @property
    def total_time(self) -> float:
        return self.levels[-1].elapsed if self.levels else 0.0


def check_settings(*, theta=0.5, target=None, max_dofs=None, max_time=None, max_levels=None,
                   estimator: str = "residual", refinement: str = "adaptive") -> dict:
    """Validate the settings of :func:`adaptive_solve`; the normalised values.

    Raises
    ------
    AdaptivityError
        ``theta`` outside (0, 1]; ``target``, ``max_dofs``, ``max_time`` or ``max_levels`` not a
        positive finite number (``max_dofs``, ``max_levels`` integers); an unknown refinement.
    UnknownNameError
        An unknown estimator (the valid names listed).
    """
    out = {"theta": check_theta(theta), "estimator": estimator, "refinement": refinement}
    ESTIMATORS.get(estimator)
    if refinement not in REFINEMENTS:
        raise AdaptivityError(f"unknown refinement {refinement!r}; valid: {', '.join(REFINEMENTS)}")
    for name, value, integer in (("target", target, False), ("max_dofs", max_dofs, True),
                                 ("max_time", max_time, False), ("max_levels", max_levels, True)):
        if value is None:
            out[name] = None
            continue
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise AdaptivityError(f"{name} must be a positive number, got {value!r}") from None
        if isinstance(value, bool) or not (v > 0) or not math.isfinite(v) or (integer and v != int(v)):
            kind = "a positive integer" if integer else "a positive finite number"
            raise AdaptivityError(f"{name} must be {kind}, got {value!r}")
        out[name] = int(v) if integer else v
    return out


def adaptive_solve(solve_on: Callable, mesh, *, theta: float = 0.5, target: float | None = None,
                   max_dofs: int | None = None, max_time: float | None = None,
                   max_levels: int | None = 30, estimator: str = "residual",
                   refinement: str = "adaptive", grad_exact: Callable | None = None,
                   target_on: str = "estimate", callback: Callable | None = None) -> AdaptiveResult:
    """Solve, estimate, mark and refine until the estimate meets ``target`` or a budget is spent.

    Parameters
    ----------
    solve_on : callable ``(mesh, x0) -> (problem, u, result)``
        Builds and solves the problem on ``mesh``; ``x0`` is the previous level's solution
        interpolated to ``mesh`` (``None`` on the first level, and for P2), ``problem`` a
        :class:`~femkit.fem.PoissonProblem` (its data feed the estimator; a P2 problem gets the
        P2 residual estimator and energy error), ``u`` the solution and ``result`` the solver's
        :class:`~femkit.solvers.SolveResult`.
    mesh : Mesh
        The initial mesh (its triangles are relabelled longest-edge-first for bisection).
    theta : float in (0, 1]
        Dörfler fraction: refine the fewest elements holding ``theta`` of the squared estimate.
    target : float > 0, optional
        Stop as soon as the estimate is ``<= target`` (``target_met = True``).
    max_dofs : int > 0, optional
        Never solve a mesh with more than ``max_dofs`` nodes: stop before it.
    max_time : float > 0, optional
        Stop after the first level that ends past ``max_time`` seconds of wall time.
    max_levels : int > 0, optional
        At most this many solves (default 30).
    estimator : ``residual`` or ``zz``
    refinement : ``adaptive`` (Dörfler + newest-vertex bisection) or ``uniform`` (red refinement).
    grad_exact : callable ``(x, y) -> (du/dx, du/dy)``, optional
        Exact gradient: each level records the true energy error and the effectivity.
    target_on : ``estimate`` (default) or ``error``
        What ``target`` is compared with; ``error`` (the true energy error, needs ``grad_exact``)
        serves benchmarks and studies that compare refinements at equal true accuracy.
    callback : callable ``(LevelRecord) -> None``, optional
        Called after each level (progress reports).

    Returns
    -------
    AdaptiveResult
        Hitting a budget before ``target`` is not an error: ``target_met`` is False and
        ``stop_reason`` says which budget.
    """
    from ...mesh.bisect import bisect, label_longest_edge
    from ..estimators import estimate
    from ..lagrange import element_energy_error
    from ..norms import energy_error

    settings = check_settings(theta=theta, target=target, max_dofs=max_dofs, max_time=max_time,
                              max_levels=max_levels, estimator=estimator, refinement=refinement)
    estimate_fn = ESTIMATORS.get(estimator)
    if target_on not in ("estimate", "error") or (target_on == "error" and grad_exact is None):
        raise AdaptivityError(f"target_on must be 'estimate', or 'error' with an exact gradient; "
                              f"got {target_on!r}")
    settings["target_on"] = target_on
    state = None                                   # tetrahedra: the bisection state (Maubach)
    if refinement == "adaptive" and mesh.dim == 3:
        from ...mesh.bisect3d import TetBisection

        state = TetBisection.start(mesh)
    elif refinement == "adaptive":
        mesh = label_longest_edge(mesh)
    levels: list[LevelRecord] = []
    x0 = None
    t_start = time.perf_counter()
    excluded = 0.0                                 # true-error evaluation is not part of the run
    while True:
        t0 = time.perf_counter()
        problem, u, result = solve_on(mesh, x0)
        t1 = time.perf_counter()
        higher = getattr(getattr(problem, "element", None), "name", "P1") != "P1"   # P2: its own
        est = (estimate(problem, u, estimator) if higher
               else estimate_fn(mesh, u, **problem_data(problem)))
        t2 = time.perf_counter()
        error = eff = None
        if grad_exact is not None:
            error = (element_energy_error(mesh, u, grad_exact, problem.kappa, element=problem.element)
                     if higher else energy_error(mesh, u, grad_exact, problem.kappa))
            eff = est.effectivity(error)
        elapsed = t2 - t_start - excluded          # earlier levels' true-error evaluations removed
        excluded += time.perf_counter() - t2
        system = problem.system
        rec = LevelRecord(level=len(levels), n_elements=mesh.n_cells, n_nodes=mesh.n_points,
                          dofs=int(system.A.shape[0]) if system is not None else mesh.n_points,
                          estimate=est.energy, error=error, effectivity=eff,
                          iterations=int(getattr(result, "iterations", 0)),
                          converged=bool(getattr(result, "converged", True)),
                          solve_time=t1 - t0, estimate_time=t2 - t1, refine_time=0.0,
                          elapsed=elapsed, min_angle=_min_angle(mesh))
        levels.append(rec)
        stop = _stop_reason(settings, rec, len(levels))
        marked = None
        if stop is None:
            t3 = time.perf_counter()
            if refinement == "adaptive":
                marked = dorfler_mark(est.indicators, settings["theta"])
                if not len(marked):
                    stop = "no_marked"
                else:
                    step = bisect(mesh, marked) if state is None else state.refine(marked)
            else:
                step = _uniform_step(mesh)
            if stop is None:
                if settings["max_dofs"] is not None and step.mesh.n_points > settings["max_dofs"]:
                    stop = "max_dofs"
                rec.refine_time = time.perf_counter() - t3
                rec.marked = int(len(marked)) if marked is not None else mesh.n_cells
        if callback is not None:
            callback(rec)
        if stop is not None:
            return AdaptiveResult(levels=levels, mesh=mesh, u=u, problem=problem, estimate=est,
                                  target_met=stop == "target", stop_reason=stop, settings=settings,
                                  result=result)
        # a P2 solution (one value per dof) has no nodal prolongation here: the next level starts cold
        x0 = None if len(u) != mesh.n_points else step.prolong(u)
        mesh = step.mesh
        state = step if state is not None else None


def _min_angle(mesh) -> float:
    """Smallest triangle angle (2D) or dihedral angle (3D) of ``mesh``, in degrees."""
    from ...mesh.quality import dihedral_angles, side_lengths_and_angles

    p = mesh.points[mesh.cells]
    return float(np.min(dihedral_angles(p) if mesh.dim == 3 else side_lengths_and_angles(p)[1]))


def _stop_reason(settings: dict, rec: LevelRecord, n_levels: int) -> str | None:
    measured = rec.error if settings["target_on"] == "error" else rec.estimate
    if settings["target"] is not None and measured <= settings["target"]:
        return "target"
    if settings["max_time"] is not None and rec.elapsed >= settings["max_time"]:
        return "max_time"
    if settings["max_levels"] is not None and n_levels >= settings["max_levels"]:
        return "max_levels"
    return None


def _uniform_step(mesh):
    """Uniform red refinement as a :class:`~femkit.mesh.bisect.Bisection` (same prolongation)."""
    from ...mesh.bisect import Bisection
    from ...mesh.edges import edges
    from ...mesh.refine import refine

    edge_nodes, _ = edges(mesh)
    return Bisection(mesh=refine(mesh), parent=np.repeat(np.arange(mesh.n_cells), 2 ** mesh.dim),
                     new_node_edges=edge_nodes)


def problem_solver(make_problem: Callable, solve: Callable, method: str = "pcg") -> Callable:
    """A ``solve_on(mesh, x0)`` for :func:`adaptive_solve` from a problem builder and a solver.

    Parameters
    ----------
    make_problem : callable ``mesh -> PoissonProblem``
        Builds the problem on each level's mesh (an application's own translation of its input).
    solve : callable ``(A, b, x0) -> SolveResult``
        The linear solver (e.g. :meth:`femkit.solvers.SolverSpec.solve`).
    method : str
        Solver name: the system is reduced for it (pure Neumann: bordered only for ``direct``), and
        ``x0`` (the full nodal vector) is restricted to the system's unknowns unless it is ``direct``.
    """
    def solve_on(mesh, x0=None):
        problem = make_problem(mesh)
        system = problem.reduce(*problem.assemble_matrices(), method=method)
        start = None
        if x0 is not None and method != "direct":
            start = np.asarray(x0, dtype=np.float64)[system.free]
            if start.shape != (system.A.shape[0],):
                start = None                      # bordered system: no nodal start
        result = solve(system.A, system.b, start)
        return problem, system.expand(result.x), result

    return solve_on


def poisson_solver(kappa=1.0, f=0.0, *, dirichlet: Sequence = ((None, 0.0),), neumann: Sequence = (),
                   nullspace: str | None = None, load_rule: str = "barycentric",
                   method: str = "pcg", preconditioner=None, **solver_opts) -> Callable:
    """A ``solve_on(mesh, x0)`` for :func:`adaptive_solve` from Poisson data.

    Arguments as in :class:`~femkit.fem.PoissonProblem` and :func:`femkit.solvers.solve`
    (``kappa`` must not be a per-element array: the mesh changes; use a number, a region table or
    a callable). ``x0`` (full nodal vector) is restricted to the unknowns of the reduced system and
    handed to the solver as its initial guess.
    """
    from ...solvers import solve
    from ..poisson import PoissonProblem

    if isinstance(kappa, np.ndarray) and kappa.ndim > 0:
        raise AdaptivityError("kappa must be a number, a region table or a callable for adaptive "
                              "refinement (a per-element array does not follow the mesh)")

    def make_problem(mesh):
        return PoissonProblem(mesh, kappa, f, dirichlet=dirichlet, neumann=neumann,
                              nullspace=nullspace, load_rule=load_rule)

    def solve_system(A, b, x0):
        return solve(A, b, x0, method=method, preconditioner=preconditioner, **solver_opts)

    return problem_solver(make_problem, solve_system, method)
