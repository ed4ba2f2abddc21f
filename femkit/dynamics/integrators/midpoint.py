"""Explicit midpoint (SOFA's RungeKutta2): slope at an Euler half step.

``x+ = x + h v_{1/2}``, ``v+ = v + h a(x_{1/2}, v_{1/2})`` with ``x_{1/2} = x + h/2 v``,
``v_{1/2} = v + h/2 a``. Second order; Dahlquist real interval ``[-2, 0]``; never stable on
the undamped oscillator (same amplification as Heun on linear problems).
"""

from __future__ import annotations

from dataclasses import dataclass

from .registry import register
from .runge_kutta import ButcherTableau, ExplicitRungeKutta


@register("midpoint")
@dataclass(frozen=True)
class Midpoint(ExplicitRungeKutta):
    order = 2
    stability_bound = 2.0
    #: its stability region misses the imaginary axis: unstable on the undamped oscillator at
    #: every step size (``stability_bound`` is the real interval, for the critical-step warning)
    oscillator_stable = False
    tableau = ButcherTableau(((0.0, 0.0), (0.5, 0.0)), (0.0, 1.0), (0.0, 0.5))
