"""Velocity Verlet: ``x+ = x + h v + h^2/2 a``, ``v+ = v + h/2 (a + a+)``.

Written as kick-drift-kick (:mod:`.kick_drift_kick`): ``v_{1/2} = v + h/2 a``,
``x+ = x + h v_{1/2}``, ``v+ = v_{1/2} + h/2 a+``. One force evaluation per step (the new
acceleration is kept for the next step). Forces that depend on velocity see the predictor
``v + h a``. Second order, symplectic; stable for ``h omega < 2``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import StepContext, StepperState
from .kick_drift_kick import KickDriftKick
from .registry import register


@register("velocity_verlet")
@dataclass(frozen=True)
class VelocityVerlet(KickDriftKick):

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        a = state.aux["a"]
        v_half = state.v + (0.5 * dt) * a
        x_new, a_new, v_new = self.drift_kick(system, state.x, v_half, state.v + dt * a,
                                              state.t + dt, dt)
        return StepperState(x_new, v_new, state.t + dt, {"a": a_new})
