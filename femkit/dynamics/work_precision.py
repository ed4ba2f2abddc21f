"""Cloth work-precision: which implicit method buys the most accuracy per millisecond.

Every method runs the same cloth for the same frames at the same ``dt`` (one step per frame) and
is charged its median wall time per frame. Two errors per run, both per frame
(``max_i |x_i(t) - x_i^ref(t)| / L``, ``L`` the bounding-box diagonal of ``x0``, averaged over the
frames):

* **solve error** against implicit Euler solved by Newton to a tight tolerance at the *same*
  ``dt``: what each method loses by solving the backward-Euler equations approximately (fast
  mass-spring after ``k`` local/global iterations, Liu et al. 2013; with Chebyshev acceleration,
  Wang 2015; Baraff-Witkin's single linearised step, Baraff & Witkin 1998; Newton stopped after
  ``k`` iterations);
* **trajectory error** against a small-``dt`` run of a second-order method (Newmark's trapezoidal
  rule or RK4, ``substeps`` steps per frame): what the user sees, discretisation error included
  (first-order implicit Euler's numerical damping dominates it at large ``dt``).

The result also carries the total-energy history of every run. The study layer
(``femkit.study``) computes the Pareto fronts, draws and writes; this module computes only.
"""

from __future__ import annotations

import statistics
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..solvers.spec import SolverSpec
from .integrators import INTEGRATORS, StepContext, get_integrator

__all__ = ["MethodRun", "FAMILIES", "method_families", "expand_methods", "cloth_work_precision"]


def method_families() -> dict[str, tuple[str, str, str | None, dict]]:
    """The method families, as the integrators declare them (``Integrator.work_precision``):
    family -> ``(label prefix, integrator name, the option the sweep varies or None, options
    every run of the family takes)``, integrator by integrator in name order.

    >>> list(method_families())
    ['fast_mass_spring', 'chebyshev', 'baraff_witkin', 'newton']
    """
    return {family: (label, name, knob, dict(fixed)) for name in INTEGRATORS.names()
            for family, (label, knob, fixed) in INTEGRATORS.get(name).work_precision.items()}


def __getattr__(name: str):
    """``FAMILIES``: :func:`method_families` now (a plugin's integrator included)."""
    if name == "FAMILIES":
        return method_families()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass
class MethodRun:
    """One point of the study: a method with one setting, its cost, errors and energies."""

    family: str
    label: str
    integrator: str
    options: dict
    setting: int | None = None
    time_per_frame: float = float("nan")
    solve_error: float = float("nan")
    trajectory_error: float = float("nan")
    energy: list = field(default_factory=list)
    failed: str = ""
    solver: SolverSpec | None = None    # this method's linear solver (None: the study's)

    def summary(self) -> dict:
        return {"family": self.family, "label": self.label, "integrator": self.integrator,
                "options": self.options, "setting": self.setting,
                "time_per_frame": self.time_per_frame, "solve_error": self.solve_error,
                "trajectory_error": self.trajectory_error, "failed": self.failed,
                "linear_solver": "" if self.solver is None else " ".join(
                    [self.solver.method] + [f"{k}={v}" for k, v in self.solver.options.items()])}


def expand_methods(spec: list[dict]) -> list[MethodRun]:
    """One :class:`MethodRun` per (family, setting) of a list like
    ``[{"family": "fast_mass_spring", "iterations": [1, 2, 5]}, {"family": "baraff_witkin"},
    {"family": "newton", "iterations": [1, 2, 3]}]``.

    ``iterations`` is the local/global sweeps (fast mass-spring, Chebyshev) or the Newton
    iterations per step; ``options`` (optional) are extra integrator options;
    ``linear_solver`` (optional, a :class:`~femkit.solvers.SolverSpec`) replaces the study's
    linear solver for this family (e.g. the ``pardiso`` Cholesky engine for Newton only).
    """
    runs = []
    for item in spec:
        fam = item.get("family")
        families = method_families()
        if fam not in families:
            from ..errors import UnknownNameError

            raise UnknownNameError("work-precision method family", str(fam), families)
        prefix, integ, knob, fixed = families[fam]
        extra = dict(item.get("options") or {})
        own = item.get("linear_solver")
        if own is not None and not isinstance(own, SolverSpec):
            raise InputError(f"method family {fam!r}: linear_solver must be a SolverSpec, got "
                             f"{type(own).__name__}")
        if knob is None:
            runs.append(MethodRun(fam, prefix, integ, _with_fixed(extra, fixed), solver=own))
            continue
        its = item.get("iterations")
        if not its or any(int(k) < 1 for k in its):
            raise InputError(f"method family {fam!r} needs iterations: a list of integers >= 1")
        for k in its:
            opts = _with_fixed({**extra, knob: int(k)}, fixed)
            runs.append(MethodRun(fam, f"{prefix} {k} it", integ, opts, setting=int(k), solver=own))
    return runs


def _with_fixed(options: dict, fixed: dict) -> dict:
    """``options`` and, after them, the family's ``fixed`` options the file did not set."""
    return {**options, **{k: v for k, v in fixed.items() if k not in options}}


def _trajectory(system, name, opts, dt, frames, solver, substeps=1):
    """Positions at every frame (``frames + 1`` of them), seconds per frame (median after a
    warm-up step) and total energies; ``solver`` a method name or a whole SolverSpec."""
    ctx = StepContext(solver if isinstance(solver, SolverSpec) else SolverSpec(solver))
    integ = get_integrator(name, **opts)
    h = dt / substeps
    s = integ.start(system, system.x0, system.v0, 0.0, h, ctx)
    xs, energies, times = [s.x.copy()], [system.energies(s.x, s.v)["total"]], []
    for _ in range(frames):
        t0 = time.perf_counter()
        for _ in range(substeps):
            s = integ.step(system, s, h, ctx)
        times.append(time.perf_counter() - t0)
        if not np.all(np.isfinite(s.x)):
            raise FloatingPointError("non-finite state")
        xs.append(s.x.copy())
        energies.append(system.energies(s.x, s.v)["total"])
    per_frame = statistics.median(times[1:]) if len(times) > 1 else times[0]
    return np.array(xs), per_frame, energies


def _frame_error(xs, ref, length) -> float:
    err = np.abs(xs[1:] - ref[1:]).max(axis=(1, 2)) / length
    return float(err.mean())


def cloth_work_precision(system, dt: float, frames: int, methods: list[dict], *,
                         solver: str | SolverSpec = "cholesky", reference_tol: float = 1e-10,
                         trajectory_reference: str = "newmark", substeps: int = 16,
                         reference_solve: str = "newton", progress=None) -> dict:
    """Run the study on one system (see the module docstring).

    Parameters
    ----------
    system : MassSpringSystem
    dt : float
        Step = frame length of every method and of the solve reference.
    frames : int
        Frames simulated (one step each).
    methods : list of dict
        See :func:`expand_methods`.
    solver : str or SolverSpec
        Linear solver of the implicit methods and of the solve reference (``"cholesky"``: the
        compiled path; a SolverSpec keeps its options, e.g. the Cholesky engine); a method
        family's own ``linear_solver`` replaces it for that family.
    reference_tol : float
        Tolerance of the implicit Euler reference (``||dx||_inf <= tol L``).
    reference_solve : {"newton", "local_global"}
        How the implicit Euler reference is solved: Newton (with the clamp; it converges only
        linearly where many springs are compressed: 31-60 iterations per step on Liu's falling
        cloth), or local/global iterations with Chebyshev acceleration run to the tolerance (the
        same fixed point, tested equal to Newton's step; cheap iterations).
    trajectory_reference : {"newmark", "rk4"}
        The small-``dt`` reference, ``substeps`` steps per frame.
    progress : callable, optional
        Called with each finished run's label.

    Returns
    -------
    dict
        ``runs`` (list of :class:`MethodRun`), ``reference`` (time per frame and energies of the
        two references), ``times`` (frame times) and ``length`` (``L``).
    """
    if not dt > 0 or int(frames) < 1:
        raise InputError(f"need dt > 0 and frames >= 1, got dt={dt!r}, frames={frames!r}")
    if trajectory_reference not in ("newmark", "rk4"):
        raise InputError(f"trajectory_reference must be 'newmark' or 'rk4', got {trajectory_reference!r}")
    frames = int(frames)
    runs = expand_methods(methods)
    length = float(np.linalg.norm(np.ptp(system.x0, axis=0))) or 1.0
    if reference_solve == "newton":
        ref_name, ref_opts = "newton", {"tol": reference_tol, "max_iterations": 100}
    elif reference_solve == "local_global":
        ref_name, ref_opts = "fast_mass_spring", {"iterations": 100_000, "tol": reference_tol,
                                                  "chebyshev": True}
    else:
        raise InputError(f"reference_solve must be 'newton' or 'local_global', got {reference_solve!r}")
    ie, t_ie, e_ie = _trajectory(system, ref_name, ref_opts, dt, frames, solver)
    # the trajectory reference is not timed against anything: SuperLU takes any matrix Newmark's
    # implicit step forms (no definiteness fix there)
    tr, t_tr, e_tr = _trajectory(system, trajectory_reference, {}, dt, frames, "direct",
                                 substeps=int(substeps))
    for run in runs:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")   # Newton stopped at k iterations is the point
                xs, run.time_per_frame, run.energy = _trajectory(system, run.integrator, run.options,
                                                                 dt, frames, run.solver or solver)
            run.solve_error = _frame_error(xs, ie, length)
            run.trajectory_error = _frame_error(xs, tr, length)
        except (FloatingPointError, ArithmeticError) as exc:
            run.failed = str(exc) or type(exc).__name__
        if progress is not None:
            progress(run.label)
    return {
        "runs": runs,
        "reference": {"implicit_euler": {"time_per_frame": t_ie, "energy": e_ie, "tol": reference_tol,
                                         "solve": reference_solve},
                      "trajectory": {"method": trajectory_reference, "substeps": int(substeps),
                                     "time_per_frame": t_tr, "energy": e_tr,
                                     "error_vs_implicit_euler": _frame_error(ie, tr, length)}},
        "times": [dt * k for k in range(frames + 1)],
        "length": length,
    }
