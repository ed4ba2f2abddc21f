"""Heun's method (explicit trapezoid, RK2): average of the slopes at ``t`` and at an Euler predictor.

Second order; Dahlquist real interval ``[-2, 0]``; never stable on the undamped oscillator
(energy grows as ``1 + (h omega)^4 / 4`` per step).
"""

from __future__ import annotations

from dataclasses import dataclass

from .registry import register
from .runge_kutta import ButcherTableau, ExplicitRungeKutta


@register("heun")
@dataclass(frozen=True)
class Heun(ExplicitRungeKutta):
    order = 2
    stability_bound = 2.0
    #: its stability region misses the imaginary axis: unstable on the undamped oscillator at
    #: every step size (``stability_bound`` is the real interval, for the critical-step warning)
    oscillator_stable = False
    tableau = ButcherTableau(((0.0, 0.0), (1.0, 0.0)), (0.5, 0.5), (0.0, 1.0))
