"""Run an integrator over time with stability checked, never assumed.

:func:`simulate` advances a :class:`~femkit.dynamics.system.MassSpringSystem` with a registered
integrator and records positions, velocities and energies. Before an explicit method runs it
estimates ``omega_max`` (power iteration, :mod:`femkit.dynamics.stability`) and warns with a
:class:`StabilityWarning` naming ``omega_max`` and the critical step when ``dt`` exceeds it.
While running it stops with :class:`~femkit.errors.InstabilityError` on a non-finite state or
when the total energy grows by more than ``energy_growth_limit`` times the run's energy scale;
the error carries the trajectory up to the last good step (never a NaN).

Energy scale (works when the initial energy is ~0, e.g. a cloth at rest at height 0)::

    scale = max(|E_0|, |K_0| + |U_spring| + |U_gravity| + |U_contact|, sum_i |f_i(x_0)| * diam(x_0))

and the energy ratio is ``(E_t - E_0) / scale`` (only growth counts).

>>> from femkit.dynamics.topology import single_spring
>>> traj = simulate(single_spring(), "newmark", 1e-2, 0.1)
>>> traj.steps, traj.x.shape, bool(traj.completed)
(10, (11, 2, 2), True)
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, InstabilityError, StabilityWarning  # StabilityWarning re-exported
from .integrators import Integrator, StepContext, get_integrator

__all__ = ["simulate", "Trajectory", "StabilityWarning"]

_ENERGY_KEYS = ("kinetic", "spring", "gravity", "contact", "total")


@dataclass
class Trajectory:
    """Recorded run: ``times (m,)``, ``x``/``v`` ``(m, n, d)``, ``energies`` ``{key: (m,)}``.

    ``steps`` is the number of steps taken, ``completed`` False when the run stopped on an
    instability (then ``reason`` says why); ``omega_max``/``dt_crit`` are the stability estimates
    (``None`` when not computed); ``stats`` holds the integrator counters (factorisations,
    linear solves, Newton iterations); ``momentum`` ``(m, d)``.
    """

    method: str
    dt: float
    times: np.ndarray
    x: np.ndarray
    v: np.ndarray
    energies: dict
    momentum: np.ndarray
    steps: int
    wall_time: float
    completed: bool = True
    reason: str = ""
    omega_max: float | None = None
    dt_crit: float | None = None
    energy_scale: float = 1.0
    stats: dict = field(default_factory=dict)

    @property
    def energy_drift(self) -> float:
        """``(E_end - E_0) / energy_scale``."""
        e = self.energies["total"]
        return float((e[-1] - e[0]) / self.energy_scale) if len(e) else 0.0

    def summary(self) -> dict:
        """JSON-ready facts (no arrays)."""
        return {
            "method": self.method, "dt": self.dt, "steps": int(self.steps),
            "recorded": int(len(self.times)), "wall_time": float(self.wall_time),
            "completed": bool(self.completed), "reason": self.reason,
            "omega_max": self.omega_max, "dt_crit": self.dt_crit,
            "energy_drift": self.energy_drift,
            "stats": {k: (v if not isinstance(v, list) else {"total": int(sum(v)), "max": int(max(v, default=0))})
                      for k, v in self.stats.items()},
        }


class _Recorder:
    def __init__(self, system):
        self.system = system
        self.times, self.xs, self.vs, self.mom = [], [], [], []
        self.energies = {k: [] for k in _ENERGY_KEYS}

    def add(self, t, x, v, e):
        self.times.append(t)
        self.xs.append(x.copy())
        self.vs.append(v.copy())
        self.mom.append(self.system.momentum(v))
        for k in _ENERGY_KEYS:
            self.energies[k].append(e[k])

    def build(self, method, dt, steps, wall, **kw) -> Trajectory:
        n, d = self.system.n, self.system.dim
        return Trajectory(
            method=method, dt=dt, times=np.array(self.times, dtype=float),
            x=np.array(self.xs, dtype=float).reshape(-1, n, d),
            v=np.array(self.vs, dtype=float).reshape(-1, n, d),
            energies={k: np.array(v, dtype=float) for k, v in self.energies.items()},
            momentum=np.array(self.mom, dtype=float).reshape(-1, d),
            steps=steps, wall_time=wall, **kw)


def _energy_scale(system, x, v, e0) -> float:
    parts = sum(abs(e0[k]) for k in ("kinetic", "spring", "gravity", "contact"))
    f = system.force(x, v, 0.0)
    diam = float(np.linalg.norm(np.ptp(x, axis=0)))
    work = float(np.abs(f).sum()) * diam
    scale = max(abs(e0["total"]), parts, work)
    return scale if scale > 0.0 else 1.0


def simulate(system, integrator, dt: float, t_end: float, *, ctx: StepContext | None = None,
             record_every: int = 1, energy_growth_limit: float = 100.0,
             check_stability: bool = True, check_every: int = 10, progress: bool = False,
             x0=None, v0=None, t0: float = 0.0, **integrator_options) -> Trajectory:
    """Integrate ``system`` from ``t0`` to ``t_end`` with fixed step ``dt``.

    Parameters
    ----------
    system : MassSpringSystem
    integrator : str or Integrator
        A name in :data:`~femkit.dynamics.integrators.INTEGRATORS` (built with
        ``integrator_options``) or an integrator object.
    dt, t_end : float
        Step and end time; ``round((t_end - t0) / dt)`` steps are taken.
    ctx : StepContext, optional
        Linear solver and caches (default: direct solver).
    record_every : int
        Record every ``record_every``-th step (the start and the last step always).
    energy_growth_limit : float
        Stop when ``(E_t - E_0) / scale`` exceeds it (checked every ``check_every`` steps and
        at every recorded step); ``inf`` disables the energy check (finiteness is always checked).
    check_stability : bool
        For explicit methods: estimate ``omega_max`` and warn when ``dt`` exceeds the critical step.
    progress : bool
        Show a tqdm progress bar (only when stderr is a terminal).
    x0, v0, t0 : initial state (default the system's ``x0``, ``v0`` and 0).

    Returns
    -------
    Trajectory

    Raises
    ------
    InstabilityError
        Non-finite state or energy growth; ``partial`` is the trajectory up to the last good step.
    InputError
        Non-positive ``dt``, ``t_end < t0``, ``record_every < 1``.
    """
    if not isinstance(integrator, Integrator):
        integrator = get_integrator(str(integrator), **integrator_options)
    elif integrator_options:
        raise InputError("integrator options are only accepted with an integrator name")
    dt = float(dt)
    if not (math.isfinite(dt) and dt > 0.0):
        raise InputError(f"dt must be a positive finite number, got {dt}")
    if not (math.isfinite(float(t_end)) and t_end >= t0):
        raise InputError(f"t_end must be finite and >= t0 = {t0}, got {t_end}")
    if int(record_every) < 1 or int(check_every) < 1:
        raise InputError("record_every and check_every must be >= 1")
    record_every, check_every = int(record_every), int(check_every)
    ctx = ctx if ctx is not None else StepContext()
    n_steps = int(round((float(t_end) - t0) / dt))
    method = integrator.name

    omega_max = dt_crit = None
    if check_stability and not integrator.implicit:
        from .stability import critical_dt, estimate_omega_max

        omega_max = float(estimate_omega_max(system, system.x0 if x0 is None else x0))
        dt_crit = float(critical_dt(omega_max, integrator.stability_bound))
        if dt > dt_crit:
            warnings.warn(StabilityWarning(
                f"{method}: dt = {dt:.4g} exceeds the critical step {dt_crit:.4g} "
                f"(= {integrator.stability_bound:.4g} / omega_max, omega_max = {omega_max:.4g}, "
                f"h*omega_max = {dt * omega_max:.4g}); expect the run to blow up"), stacklevel=2)

    x_init = system.x0 if x0 is None else x0
    v_init = system.v0 if v0 is None else v0
    state = integrator.start(system, x_init, v_init, t0, dt, ctx)
    rec = _Recorder(system)
    e0 = system.energies(state.x, state.v)
    scale = _energy_scale(system, state.x, state.v, e0)
    rec.add(state.t, state.x, state.v, e0)

    bar = None
    if progress and sys.stderr.isatty():
        from tqdm import tqdm

        bar = tqdm(total=n_steps, desc=method, unit="step", leave=False)
    start = time.perf_counter()
    last_recorded = 0
    common = dict(omega_max=omega_max, dt_crit=dt_crit, energy_scale=scale, stats=ctx.stats)

    def fail(step, t, ratio, reason, good):
        if last_recorded != step - 1:
            rec.add(good.t, good.x, good.v, system.energies(good.x, good.v))
        partial = rec.build(method, dt, step - 1, time.perf_counter() - start,
                            completed=False, reason=reason, **common)
        raise InstabilityError(method, step, t, ratio, dt, dt_crit, reason, partial)

    try:
        for step in range(1, n_steps + 1):
            new = integrator.step(system, state, dt, ctx)
            if not (np.isfinite(new.x).all() and np.isfinite(new.v).all()):
                fail(step, new.t, math.inf, "non-finite state", state)
            record = step % record_every == 0 or step == n_steps
            e = None
            if record or step % check_every == 0:
                e = system.energies(new.x, new.v)
                ratio = (e["total"] - e0["total"]) / scale
                if not math.isfinite(e["total"]):
                    fail(step, new.t, math.inf, "non-finite energy", state)
                if ratio > energy_growth_limit:
                    fail(step, new.t, ratio,
                         f"energy grew by {ratio:.3g} x the energy scale (limit {energy_growth_limit:g})",
                         state)
            state = new
            if record:
                rec.add(state.t, state.x, state.v, e)
                last_recorded = step
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return rec.build(method, dt, n_steps, time.perf_counter() - start, **common)
