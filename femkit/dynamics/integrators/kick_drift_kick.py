"""The kick-drift-kick core shared by the Verlet family.

``verlet``, ``velocity_verlet``, ``leapfrog`` and ``central_difference`` are one scheme written
four ways: with the half-step velocity ``v_{n+1/2}``::

    kick   v_{n+1/2} = v_n + h/2 a_n          (each method forms v_{n+1/2} its own way)
    drift  x_{n+1}   = x_n + h v_{n+1/2}      (position Verlet: x_{n+1} = 2 x_n - x_{n-1} + h^2 a_n)
    kick   v_{n+1}   = v_{n+1/2} + h/2 a_{n+1},  a_{n+1} = a(x_{n+1}, v_seen)

Second order, symplectic, explicit; stable on the undamped oscillator for ``h omega < 2``.
:class:`KickDriftKick` holds those flags and the start (``state.aux["a"] = a_0``);
:meth:`KickDriftKick.drift_kick` and :meth:`KickDriftKick.kick` are the shared second half of a
step. Each method's file says how it forms ``v_{n+1/2}``, which velocity the forces see
(``v_seen``) and what it keeps in ``state.aux``; central difference also overrides
:meth:`KickDriftKick.accel` (Rayleigh's mass part is centred in its kick).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import Integrator, StepContext, StepperState

__all__ = ["KickDriftKick"]


@dataclass(frozen=True)
class KickDriftKick(Integrator):
    """Base of the Verlet family (see the module docstring)."""

    order = 2
    implicit = False
    symplectic = True
    stability_bound = 2.0

    def accel(self, system, x: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        """The acceleration the kicks use (default: every declared force / mass)."""
        return system.acceleration(x, v, t)

    def start(self, system, x, v, t: float, dt: float, ctx: StepContext) -> StepperState:
        state = super().start(system, x, v, t, dt, ctx)
        state.aux["a"] = self.accel(system, state.x, state.v, state.t)
        return state

    def kick(self, system, x_new: np.ndarray, v_half: np.ndarray, v_seen: np.ndarray,
             t_new: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Closing half kick: ``a+ = accel(x+, v_seen, t+)``, ``v+ = v_half + h/2 a+``."""
        a_new = self.accel(system, x_new, v_seen, t_new)
        return a_new, v_half + (0.5 * dt) * a_new

    def drift_kick(self, system, x: np.ndarray, v_half: np.ndarray, v_seen: np.ndarray,
                   t_new: float, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Drift ``x+ = x + h v_half`` then :meth:`kick`; returns ``(x+, a+, v+)``."""
        x_new = x + dt * v_half
        a_new, v_new = self.kick(system, x_new, v_half, v_seen, t_new, dt)
        return x_new, a_new, v_new
