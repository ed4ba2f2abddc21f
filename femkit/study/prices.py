"""The prices study plans sum (:mod:`femkit.study.cost`, the stress-case types of
:data:`femkit.study.stability.cases.STRESS_CASES`): a Poisson run on a mesh of ``triangles`` and a
sequence of time steps on a small particle system, both from the cost model's constants
(:mod:`femkit.cost`), from numbers alone.
"""

from __future__ import annotations

from ..cost import plan_poisson

__all__ = ["poisson_run_seconds", "steps_seconds", "implicit_run_seconds", "solves_per_step"]


def poisson_run_seconds(triangles: float, solver=None, *, assemble: bool = True,
                        solve: bool = True) -> float:
    """Seconds of one Poisson run on ``triangles`` triangles: assembly and boundary reduction
    (when ``assemble``) plus the setup and solve of ``solver`` (a :class:`SolverSpec`; None: a
    direct solve; ``solve=False``: none), without library imports (a study's warm-up pays them)."""
    from ..cost import load_constants
    from ..solvers.registry import priced_names

    method, pc = priced_names("direct", None) if solver is None else priced_names(
        solver.method, solver.preconditioner)
    rtol = None if solver is None else solver.rtol
    p = plan_poisson(triangles=max(float(triangles), 2.0), method=method, preconditioner=pc,
                     rtol=rtol, outputs=(), errors=False)
    imports = load_constants()["seconds"]["pyamg_import"]
    setup = p.stage("setup").seconds
    seconds = max(setup - imports, 0.0) if setup >= imports else setup
    seconds = seconds + p.stage("solve").seconds if solve else 0.0
    if assemble:
        seconds += p.stage("assembly").seconds + p.stage("boundary").seconds
    return seconds


def steps_seconds(steps: float, *, nodes: int, springs: int, dim: int = 2,
                  implicit: bool = False) -> float:
    """Seconds of ``steps`` time steps of a system of ``nodes`` and ``springs``
    (:func:`femkit.cost.plan_scene`'s per-step model, nothing recorded or written)."""
    from ..cost import plan_scene

    if steps <= 0:
        return 0.0
    return plan_scene(n_nodes=nodes, n_springs=springs, dim=dim, dt=1.0, t_end=float(steps),
                      every=max(int(steps), 1), outputs=(), implicit=implicit).seconds


def solves_per_step(integrator: str) -> float:
    """Linear solves per time step the integrator named ``integrator`` typically makes on the
    study scenes, as it declares (:attr:`femkit.dynamics.integrators.Integrator.solves_per_step`;
    the base class's for a name not registered)."""
    from ..dynamics.integrators import INTEGRATORS, Integrator

    return (INTEGRATORS.get(integrator) if integrator in INTEGRATORS else Integrator).solves_per_step


def implicit_run_seconds(steps: float, *, nodes: float, parts: float, integrator: str,
                         elements: bool = False) -> float:
    """Seconds of ``steps`` implicit steps on a 2D body of ``nodes`` nodes and ``parts``
    springs (or triangles: an element costs about what 3 springs cost, ``elements=True``): the
    scene model's implicit step times the solves per step of ``integrator``
    (:func:`solves_per_step`)."""
    solves = solves_per_step(integrator)
    springs = 3.0 * parts if elements else parts
    return steps_seconds(steps * solves, nodes=int(nodes), springs=int(springs), dim=2,
                         implicit=True)
