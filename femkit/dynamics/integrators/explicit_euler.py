"""Explicit (forward) Euler: ``x+ = x + h v``, ``v+ = v + h a(x, v)``.

First order. Stable on ``y' = lambda y`` for ``h lambda`` in ``[-2, 0]``; on the undamped
oscillator it is *never* stable: the energy grows by ``1 + (h omega)^2`` per step, so its
``stability_bound = 2`` is the Dahlquist real interval used for the critical-step warning only.
"""

from __future__ import annotations

from dataclasses import dataclass

from .registry import register
from .runge_kutta import ButcherTableau, ExplicitRungeKutta


@register("explicit_euler")
@dataclass(frozen=True)
class ExplicitEuler(ExplicitRungeKutta):
    order = 1
    stability_bound = 2.0
    #: its stability region misses the imaginary axis: unstable on the undamped oscillator at
    #: every step size (``stability_bound`` is the real interval, for the critical-step warning)
    oscillator_stable = False
    tableau = ButcherTableau(((0.0,),), (1.0,), (0.0,))
