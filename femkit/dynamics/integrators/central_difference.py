"""Central difference with Rayleigh mass damping (SOFA's CentralDifferenceSolver).

Half-step velocities; the Rayleigh mass term ``-r_M v`` is centred (trapezoidal) in time::

    v_{n+1/2} = c_v v_{n-1/2} + c_a a_n,   c_v = (1/h - r_M/2) / (1/h + r_M/2),
                                            c_a = 1 / (1/h + r_M/2)
    x_{n+1}   = x_n + h v_{n+1/2}

with ``a_n`` every other force at ``x_n`` divided by the mass (the Rayleigh stiffness part
``-r_K K v`` is applied explicitly with ``v_{n-1/2}``, which makes the method first order when
``r_K != 0``, as do dashpots and viscous damping). For ``r_M = 0`` this is SOFA's
``v+ = v + h a, x+ = x + h v+``. SOFA starts with ``v_{-1/2} = v_0``, which makes the method
only first order; femkit starts from ``v_{-1/2} = v_0 - h/2 (a_0 - r_M v_0)`` so that
``v_{1/2} = v_0 + h/2 a_0 + O(h^2)`` and positions are second order (without damping it then
equals leapfrog). ``state.v`` reports ``v_{n+1} = (v_{n+1/2} + h/2 a_{n+1}) / (1 + h r_M/2)``.
Stable for ``h omega < 2`` (undamped). The drift and closing half kick are the shared
:mod:`.kick_drift_kick` core with :meth:`CentralDifference.accel` as the acceleration.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import StepContext, StepperState
from .kick_drift_kick import KickDriftKick
from .registry import register


@register("central_difference")
@dataclass(frozen=True)
class CentralDifference(KickDriftKick):

    def accel(self, system, x, v, t):
        """Every force but Rayleigh's mass part, divided by the masses (zero rows on pinned nodes)."""
        _, rk = system.rayleigh
        a = system.acceleration(x, v, t, rayleigh=False)
        if rk != 0.0:
            a = a - rk * system.hessian_product(x, v) / system.mass[:, None]
            a[system.pinned_dofs] = 0.0
        return a

    def start(self, system, x, v, t, dt, ctx):
        state = super().start(system, x, v, t, dt, ctx)
        rm, _ = system.rayleigh
        state.aux["v_half"] = state.v - (0.5 * dt) * (state.aux["a"] - rm * state.v)
        return state

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        rm, _ = system.rayleigh
        denom = 1.0 / dt + 0.5 * rm
        c_v = (1.0 / dt - 0.5 * rm) / denom
        c_a = 1.0 / denom
        v_half = c_v * state.aux["v_half"] + c_a * state.aux["a"]
        x_new, a_new, v_sync = self.drift_kick(system, state.x, v_half, v_half, state.t + dt, dt)
        v_new = v_sync / (1.0 + 0.5 * dt * rm)
        return StepperState(x_new, v_new, state.t + dt, {"a": a_new, "v_half": v_half})
