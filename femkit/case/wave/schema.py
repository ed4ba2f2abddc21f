"""JSON schema of ``problem: wave`` case files: the time-dependent kinds' common keys
(:func:`femkit.case.transient.setup.transient_schema`, the integrator enum from
:data:`femkit.dynamics.mol.WAVE_INTEGRATORS`) with ``rho`` and ``initial_velocity``.
Every key is described in docs/heat_wave.md."""

from __future__ import annotations

__all__ = ["wave_schema"]


def wave_schema() -> dict:
    """The schema, its enums derived from the registries now."""
    from ...dynamics.mol import WAVE_INTEGRATORS
    from ..transient.setup import transient_schema

    return transient_schema("wave", "rho", WAVE_INTEGRATORS, {
        "initial_velocity": {"anyOf": [{"type": "number"}, {"type": "string", "minLength": 1}],
                             "default": 0.0,
                             "x-message": "expected a number or an expression string of x, y, z"}})
