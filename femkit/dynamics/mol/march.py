"""Marching a method-of-lines scheme from ``t0`` to ``t_end``: :func:`march` (fixed ``dt``) and
:func:`march_adaptive` (``dt`` chosen by the scheme's embedded error estimate).

Both keep a frame every ``every`` steps and the last one, check a stop flag between steps
(:class:`femkit.interrupt.StopFlag`: the run ends after the current step, ``interrupted``) and
stop at the first non-finite state (``failure``). The linear algebra's counters (factorisations,
solves, seconds) are the system's ``stats``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from .base import MolState, rate

__all__ = ["MarchResult", "march", "march_adaptive"]


@dataclass
class MarchResult:
    """Frames ``(t, u, v)`` kept, the steps taken (their sizes), per-step seconds, the end."""

    frames: list = field(default_factory=list)
    steps: int = 0
    dts: list = field(default_factory=list)
    errors: list = field(default_factory=list)
    rejected: int = 0
    step_seconds: float = 0.0
    interrupted: bool = False
    failure: str | None = None

    @property
    def t_reached(self) -> float:
        return self.frames[-1][0] if self.frames else math.nan

    @property
    def seconds_per_step(self) -> float:
        return self.step_seconds / self.steps if self.steps else 0.0


def _keep(result: MarchResult, state: MolState) -> None:
    result.frames.append((state.t, state.u.copy(), None if state.v is None else state.v.copy()))


def _bad(state: MolState) -> bool:
    return not np.isfinite(state.u).all()


def _start(scheme, system, u0, v0, t0, dt) -> MolState:
    return scheme.start(system, u0, t0, dt) if v0 is None else scheme.start(system, u0, v0, t0, dt)


def march(system, scheme, u0, t0: float, dt: float, steps: int, *, v0=None, every: int = 1,
          stop=None, progress=None) -> MarchResult:
    """``steps`` steps of ``dt`` from ``u0`` (and ``v0`` for a second-order scheme) at ``t0``.

    Frames at steps ``0, every, 2 every, ...`` and at the last step.
    """
    out = MarchResult()
    state = _start(scheme, system, u0, v0, t0, dt)
    _keep(out, state)
    clock = time.perf_counter()
    for k in range(1, steps + 1):
        if stop:
            out.interrupted = True
            break
        state = scheme.step(system, state, dt)
        out.steps = k
        if _bad(state):
            out.failure = f"the solution is not finite at t = {state.t:.6g} (step {k}): unstable"
            break
        if k % every == 0 or k == steps:
            _keep(out, state)
        if progress is not None:
            progress.update(1)
    out.step_seconds = time.perf_counter() - clock
    if out.frames[-1][0] != state.t and out.failure is None:
        _keep(out, state)
    return out


def march_adaptive(system, scheme, u0, t0: float, t_end: float, dt0: float, rtol_t: float, *,
                   max_steps: int = 100_000, stop=None, frame_times=None) -> MarchResult:
    """Steps chosen by the scheme's embedded error estimate ``aux["error"]``.

    A step is accepted when ``||error||_inf <= rtol_t * max(||u||_inf, floor)``, ``floor`` being
    ``1e-3`` of the largest ``|u0|`` (a decaying solution is not chased to round-off). Step sizes
    are ``dt0 * 2^k`` (halved on a rejection, doubled when the estimate is below
    ``2^-(order + 1)`` of its bound, the local error being ``O(dt^(order + 1))``), so a few kept
    factors serve the whole run; the last step ends on ``t_end``. Every accepted step is kept as
    a frame with its size and error. The march asks the scheme for its estimate
    (``aux["estimate"]``) and hands it the initial rate ``u'(t0)`` (``aux["rate"]``).
    """
    out = MarchResult()
    scale = 1e-3 * max(float(np.abs(u0).max()) if np.size(u0) else 0.0, 1e-300)
    state = scheme.start(system, u0, t0, dt0)
    state.aux["rate"] = rate(system, state.u, t0, dt0)
    state.aux["estimate"] = True
    grow = 2.0 ** -(scheme.order + 1)
    _keep(out, state)
    dt = dt0
    clock = time.perf_counter()
    eps = 1e-12 * max(1.0, abs(t_end))
    while state.t < t_end - eps and out.steps + out.rejected < max_steps:
        if stop:
            out.interrupted = True
            break
        h = min(dt, t_end - state.t)
        new = scheme.step(system, state, h)
        if _bad(new):
            out.failure = f"the solution is not finite at t = {new.t:.6g}: unstable"
            break
        err = float(np.abs(new.aux["error"]).max()) / (rtol_t * max(float(np.abs(new.u).max()), scale))
        if err > 1.0 and h > dt0 * 2.0 ** -20:
            out.rejected += 1
            dt = h / 2.0
            continue
        state = new
        out.steps += 1
        out.dts.append(h)
        out.errors.append(err)
        _keep(out, state)
        if err < grow and h == dt:
            dt = 2.0 * dt
    out.step_seconds = time.perf_counter() - clock
    if out.steps + out.rejected >= max_steps and state.t < t_end - eps:
        out.failure = f"adaptive steps: {max_steps} steps did not reach t_end (t = {state.t:.6g})"
    return out
