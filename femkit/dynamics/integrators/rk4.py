"""Classical fourth-order Runge-Kutta (SOFA's RungeKutta4).

Fourth order; Dahlquist real interval ``[-2.7853, 0]``; stable on the undamped oscillator for
``h omega < 2 sqrt(2)`` (slightly dissipative there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .registry import register
from .runge_kutta import ButcherTableau, ExplicitRungeKutta


@register("rk4")
@dataclass(frozen=True)
class RK4(ExplicitRungeKutta):
    order = 4
    stability_bound = 2.0 * math.sqrt(2.0)
    tableau = ButcherTableau(
        ((0.0, 0.0, 0.0, 0.0), (0.5, 0.0, 0.0, 0.0), (0.0, 0.5, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0)),
        (1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0),
        (0.0, 0.5, 0.5, 1.0),
    )
