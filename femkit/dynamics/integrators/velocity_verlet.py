"""Velocity Verlet: ``x+ = x + h v + h^2/2 a``, ``v+ = v + h/2 (a + a+)``.

One force evaluation per step (the new acceleration is kept for the next step). Forces that
depend on velocity see the predictor ``v + h a``. Second order, symplectic; stable for
``h omega < 2``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import Integrator, StepContext, StepperState
from .registry import INTEGRATORS


@INTEGRATORS.register("velocity_verlet")
@dataclass(frozen=True)
class VelocityVerlet(Integrator):
    name = "velocity_verlet"
    order = 2
    implicit = False
    symplectic = True
    stability_bound = 2.0

    def start(self, system, x, v, t, dt, ctx):
        state = super().start(system, x, v, t, dt, ctx)
        state.aux["a"] = system.acceleration(state.x, state.v, state.t)
        return state

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        a = state.aux["a"]
        x_new = state.x + dt * state.v + (0.5 * dt * dt) * a
        a_new = system.acceleration(x_new, state.v + dt * a, state.t + dt)
        v_new = state.v + (0.5 * dt) * (a + a_new)
        return StepperState(x_new, v_new, state.t + dt, {"a": a_new})
