"""Run an integrator over time with stability checked, never assumed.

:func:`simulate` advances a :class:`~femkit.dynamics.system.MassSpringSystem` with a registered
integrator and records positions, velocities and energies. Before an explicit method runs it
estimates ``omega_max`` (power iteration, :mod:`femkit.dynamics.stability`) and warns with a
:class:`StabilityWarning` naming ``omega_max`` and the critical step when ``dt`` exceeds it.
While running it stops with :class:`~femkit.errors.InstabilityError` when the run is judged
unstable; the error carries the trajectory up to the last good step (never a NaN).

Stability criterion
-------------------
Every quantity below is invariant to the origin of gravity's potential (shifting the whole
scene by a constant vector changes no verdict) and is meaningful when the initial energy is 0.

*Energy scale* (computed once, at the initial state ``x_0, v_0``)::

    S = K_0 + U_spring(x_0) + U_contact(x_0) + L * sum_i |f_grav,i|

with ``L = |ptp(x_0)|`` the diagonal of the bounding box of the body (its size) and
``f_grav`` the gravity force alone (per free node), so the last term is the work gravity can do
over the body's size. Kinetic, spring and contact energies are non-negative and
origin-free; gravity's potential ``-m g . x`` (origin-dependent) never enters ``S``. When
``S = 0`` (a body at rest, unstretched, without gravity) the floor
``S = 1e-12 * 1/2 sum_s k_s rest_s^2`` (springs strained by 1e-6) is used, or 1 without springs.

*Drift* ``D_t = (E_t - E_0) / S`` (total energy, so gravity's origin cancels).

The run stops at the first of

1. a non-finite position, velocity (every step) or energy (at every check);
2. ``D_t > energy_growth_limit`` (default 100) at a check (every ``check_every`` steps and
   every recorded step): "energy grew";
3. sustained geometric growth, tested on the regular checks (every ``check_every`` steps):
   ``D_j > GROWTH_FLOOR`` (0.5) and ``D_j > (1 + GROWTH_EPS) D_{j-1}`` (5 % per check) at
   ``GROWTH_CHECKS`` (8) consecutive checks: the energy above its start exceeds half the
   energy in play and keeps growing geometrically, caught long before the drift limit. The
   exact dynamics conserve (or dissipate) ``E``, so ``D`` is pure method error. The floor is
   what keeps stable runs quiet: the bounded error of a symplectic method rises from 0 like a
   power of ``t`` (ratios ``(1 + 1/j)^p`` above 1.05 for the first ``~20 p`` checks), so a
   small floor (1e-3 was tried) flags well-resolved slow runs and explicit Euler in
   convergence studies; above 0.5 only real growth remains (symplectic methods reach it only
   near their limit, where ``|D|`` oscillates fast, up to ``1/(1 - (h omega/2)^2)``).

Measured (single spring k = 100, m = 1, g = 1; ``check_every = 10``): explicit Euler at
``h omega = 0.1`` is stopped by rule 3 at step 550 (``D = 1.2``; rule 2 alone: step 1005),
Heun at ``h omega = 0.5`` at step 380 (rule 2 alone: 615). No alarm at ``0.9 dt_crit`` over
6000 steps for symplectic Euler, Verlet, leapfrog and RK4 on a spring, a stiff pre-stretched
spring and a 6 x 6 cloth (flat and hanging). Not every run past the limit is stopped: RK4 at
``1.005 dt_crit`` on the hanging cloth ends 6000 steps with ``D = 5.3`` (the growth saturates
nonlinearly), which is why ``dt_exceeds_critical`` is reported next to the verdict.

:attr:`Trajectory.dt_exceeds_critical` records ``dt > dt_crit`` (explicit methods) whether or
not growth was detected before the run ended.

>>> from femkit.dynamics.topology import single_spring
>>> traj = simulate(single_spring(), "newmark", 1e-2, 0.1)
>>> traj.steps, traj.x.shape, bool(traj.completed)
(10, (11, 2, 2), True)
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import (InputError, InstabilityError, SolverError,  # StabilityWarning re-exported
                      StabilityWarning)
from .integrators import Integrator, StepContext, get_integrator

__all__ = ["simulate", "Trajectory", "StabilityWarning", "energy_scale", "gravity_force"]

_ENERGY_KEYS = ("kinetic", "spring", "gravity", "contact", "total")


@dataclass
class Trajectory:
    """Recorded run: ``times (m,)``, ``x``/``v`` ``(m, n, d)``, ``energies`` ``{key: (m,)}``.

    ``steps`` is the number of steps taken, ``completed`` False when the run stopped on an
    instability (then ``reason`` says why); ``omega_max``/``dt_crit`` are the stability estimates
    (``None`` when not computed); ``dt_exceeds_critical`` is ``dt > dt_crit`` (``None`` when
    ``dt_crit`` was not computed), true even when the run ended before any growth was seen; ``stats`` holds the integrator counters (factorisations,
    linear solves, Newton iterations); ``momentum`` ``(m, d)``. ``interrupted`` is true when
    the run was stopped on request (``stop``, e.g. SIGTERM) before ``t_end``: the trajectory
    then holds every recorded step so far and the state at the stop (``completed`` false).
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
    dt_exceeds_critical: bool | None = None
    stats: dict = field(default_factory=dict)
    interrupted: bool = False

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
            "completed": bool(self.completed), "interrupted": bool(self.interrupted),
            "reason": self.reason,
            "omega_max": self.omega_max, "dt_crit": self.dt_crit,
            "dt_exceeds_critical": self.dt_exceeds_critical,
            "energy_drift": self.energy_drift,
            "stats": {k: (v if not isinstance(v, list) else _list_summary(v))
                      for k, v in self.stats.items()},
        }


def _list_summary(v: list) -> dict:
    """A per-step counter list as ``{total, max}``; a per-step float list (a residual) as
    ``{last, max}``."""
    if all(isinstance(a, (int, np.integer)) for a in v):
        return {"total": int(sum(v)), "max": int(max(v, default=0))}
    return {"last": float(v[-1]), "max": float(max(v))}


class _Recorder:
    def __init__(self, system, on_record=None):
        self.system = system
        self.on_record = on_record
        self.times, self.xs, self.vs, self.mom = [], [], [], []
        self.energies = {k: [] for k in _ENERGY_KEYS}

    def add(self, t, x, v, e):
        self.times.append(t)
        self.xs.append(x.copy())
        self.vs.append(v.copy())
        self.mom.append(self.system.momentum(v))
        for k in _ENERGY_KEYS:
            self.energies[k].append(e[k])
        if self.on_record is not None:  # the copies just kept: never modified afterwards
            self.on_record(len(self.times) - 1, float(t), self.xs[-1], self.vs[-1])

    def build(self, method, dt, steps, wall, **kw) -> Trajectory:
        n, d = self.system.n, self.system.dim
        return Trajectory(
            method=method, dt=dt, times=np.array(self.times, dtype=float),
            x=np.array(self.xs, dtype=float).reshape(-1, n, d),
            v=np.array(self.vs, dtype=float).reshape(-1, n, d),
            energies={k: np.array(v, dtype=float) for k, v in self.energies.items()},
            momentum=np.array(self.mom, dtype=float).reshape(-1, d),
            steps=steps, wall_time=wall, **kw)


GROWTH_FLOOR = 0.5
"""Rule 3 counts a check only when the drift ``D`` exceeds this (fraction of the scale)."""
GROWTH_EPS = 0.05
"""Rule 3: minimal growth of ``D`` per regular check."""
GROWTH_CHECKS = 8
"""Rule 3: number of consecutive growing checks that make an instability."""


def gravity_force(system, x) -> np.ndarray:
    """The force of the declared gravity-kind forces alone, ``(n, d)``, zero on pinned nodes."""
    out = np.zeros_like(np.asarray(x, dtype=float))
    zero = np.zeros_like(out)
    for f in system.forces:
        if getattr(f, "kind", None) == "gravity":
            f.add_force(x, zero, 0.0, out)
    out[system.pinned_dofs] = 0.0
    return out


def energy_scale(system, x, v, e0: dict | None = None) -> float:
    """Origin-free energy scale ``S`` of a run started at ``(x, v)`` (module docstring).

    >>> from femkit.dynamics.topology import single_spring
    >>> s = single_spring(k=100.0, m=10.0)       # at rest length: only gravity's work m g L
    >>> energy_scale(s, s.x0, s.v0)
    100.0
    """
    x = np.asarray(x, dtype=float)
    e0 = system.energies(x, v) if e0 is None else e0
    size = float(np.linalg.norm(np.ptp(x, axis=0)))
    work = size * float(np.linalg.norm(gravity_force(system, x), axis=1).sum())
    scale = abs(e0["kinetic"]) + abs(e0["spring"]) + abs(e0["contact"]) + work
    if scale > 0.0:
        return scale
    floor = 1e-12 * 0.5 * float(np.sum(np.asarray(system.k) * np.asarray(system.rest) ** 2))
    return floor if floor > 0.0 else 1.0


class _GrowthMonitor:
    """Rules 2 and 3 of the module docstring on the drift ``D = (E - E_0) / S``."""

    def __init__(self, e0: float, scale: float, limit: float):
        self.e0, self.scale, self.limit = e0, scale, limit
        self.prev = None
        self.streak = 0

    def drift(self, energy: float) -> float:
        return (energy - self.e0) / self.scale

    def verdict(self, d: float, regular: bool) -> str | None:
        """Reason to stop, or None; ``regular`` marks the every-``check_every`` checks."""
        if d > self.limit:
            return f"energy grew by {d:.3g} x the energy scale (limit {self.limit:g})"
        if not regular:
            return None
        prev, self.prev = self.prev, d
        if prev is not None and prev > GROWTH_FLOOR and d > (1.0 + GROWTH_EPS) * prev:
            self.streak += 1
        else:
            self.streak = 0
        if self.streak >= GROWTH_CHECKS and math.isfinite(self.limit):
            return (f"energy above its start grew geometrically at {self.streak} consecutive "
                    f"checks (by > {100 * GROWTH_EPS:g} % each, now {d:.3g} x the energy scale)")
        return None


def simulate(system, integrator, dt: float, t_end: float, *, ctx: StepContext | None = None,
             record_every: int = 1, energy_growth_limit: float = 100.0,
             check_stability: bool = True, check_every: int = 10, progress=False,
             stop=None, x0=None, v0=None, t0: float = 0.0, on_record=None,
             **integrator_options) -> Trajectory:
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
        Stop when the drift ``(E_t - E_0) / S`` exceeds it (checked every ``check_every`` steps
        and at every recorded step), or on sustained geometric growth of the drift (module
        docstring); ``inf`` disables both energy rules (finiteness is always checked).
    check_stability : bool
        For explicit methods: estimate ``omega_max`` and warn when ``dt`` exceeds the critical step.
    progress : bool or femkit.progress.Progress
        Report progress on stderr (:class:`femkit.progress.Progress`: a tqdm bar on a
        terminal, one line per 10 % or per minute otherwise); or a ``Progress`` to update.
    stop : callable, optional
        ``stop() -> bool`` checked between steps (e.g. a
        :class:`femkit.interrupt.StopFlag`); when true the run ends early and returns the
        trajectory so far with ``interrupted=True`` and ``completed=False`` (the state at the
        stop is recorded; ``reason`` names the signal when ``stop`` has a ``name``). Without
        ``stop``, a stop request of an enclosing :func:`femkit.interrupt.stop_on_signals` block
        raises :class:`~femkit.interrupt.Interrupted` (a study's run keeps nothing partial).
    x0, v0, t0 : initial state (default the system's ``x0``, ``v0`` and 0).
    on_record : callable, optional
        ``on_record(k, t, x, v)`` at each recorded frame ``k`` (0, 1, ...), with the recorded
        copies of the state (read-only for the callee): how a caller writes frames while the
        run goes on (a scene's writer thread) instead of after it.

    Returns
    -------
    Trajectory

    Raises
    ------
    InstabilityError
        Non-finite state or energy growth; ``partial`` is the trajectory up to the last good step.
    SolverError
        A step failed (e.g. :class:`~femkit.dynamics.integrators.base.NewtonStepError`, a matrix
        that is not SPD for ``cholesky``): raised with ``partial`` (the trajectory up to the
        state the step started from, ``completed`` false) and ``step`` set.
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
    rec = _Recorder(system, on_record)
    e0 = system.energies(state.x, state.v)
    scale = energy_scale(system, state.x, state.v, e0)
    monitor = _GrowthMonitor(e0["total"], scale, float(energy_growth_limit))
    rec.add(state.t, state.x, state.v, e0)

    bar = None
    if progress is not None and progress is not False:
        from ..progress import Progress

        bar = progress if isinstance(progress, Progress) else Progress(n_steps, method, unit="step")
    start = time.perf_counter()
    last_recorded = 0
    exceeds = None if dt_crit is None else bool(dt > dt_crit)
    common = dict(omega_max=omega_max, dt_crit=dt_crit, energy_scale=scale,
                  dt_exceeds_critical=exceeds, stats=ctx.stats)

    def fail(step, t, ratio, reason, good):
        if last_recorded != step - 1:
            rec.add(good.t, good.x, good.v, system.energies(good.x, good.v))
        partial = rec.build(method, dt, step - 1, time.perf_counter() - start,
                            completed=False, reason=reason, **common)
        raise InstabilityError(method, step, t, ratio, dt, dt_crit, reason, partial)

    stopped_at = None
    # without a stop of its own, a run inside a stop_on_signals block (a study's) raises
    # Interrupted at a stop request instead of being recorded as complete
    from ..interrupt import Interrupted, active_flag

    watch = active_flag() if stop is None else None
    try:
        for step in range(1, n_steps + 1):
            if stop is not None and stop():
                stopped_at = step - 1
                break
            if watch:
                raise Interrupted(watch, where=f"at step {step - 1} of {n_steps} of {method}")
            try:
                new = integrator.step(system, state, dt, ctx)
            except SolverError as exc:   # a failed step (Newton, a linear solve): keep the run so far
                if last_recorded != step - 1:
                    rec.add(state.t, state.x, state.v, system.energies(state.x, state.v))
                exc.step = step
                exc.partial = rec.build(method, dt, step - 1, time.perf_counter() - start,
                                        completed=False, reason=f"step {step} failed: {exc}",
                                        **common)
                raise
            if not (np.isfinite(new.x).all() and np.isfinite(new.v).all()):
                fail(step, new.t, math.inf, "non-finite state", state)
            record = step % record_every == 0 or step == n_steps
            e = None
            regular = step % check_every == 0
            if record or regular:
                e = system.energies(new.x, new.v)
                if not math.isfinite(e["total"]):
                    fail(step, new.t, math.inf, "non-finite energy", state)
                ratio = monitor.drift(e["total"])
                reason = monitor.verdict(ratio, regular)
                if reason is not None:
                    fail(step, new.t, ratio, reason, state)
            state = new
            if record:
                rec.add(state.t, state.x, state.v, e)
                last_recorded = step
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            by = getattr(stop, "name", None) or "a stop request"
            bar.close(interrupted=by if stopped_at is not None else None)
    if stopped_at is not None:
        if last_recorded != stopped_at:
            rec.add(state.t, state.x, state.v, system.energies(state.x, state.v))
        by = getattr(stop, "name", None)
        return rec.build(method, dt, stopped_at, time.perf_counter() - start, completed=False,
                         interrupted=True, reason=f"interrupted{' by ' + by if by else ''} at "
                         f"step {stopped_at} of {n_steps}", **common)
    return rec.build(method, dt, n_steps, time.perf_counter() - start, **common)
