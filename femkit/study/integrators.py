"""Facts about an integrator that more than one study kind reports (``stability``,
``dynamics_work_precision``)."""

from __future__ import annotations

__all__ = ["oscillator_bound"]


def oscillator_bound(integrator) -> float | None:
    """The largest ``h * omega`` for which ``integrator`` keeps the undamped oscillator bounded,
    None for a method that declares ``oscillator_stable = False`` (its stability region misses
    the imaginary axis: the energy grows at every step size, as ``(1 + h^2 w^2)^n`` for
    explicit Euler)."""
    return integrator.stability_bound if getattr(integrator, "oscillator_stable", True) else None
