"""JSON schema of ``problem: heat`` case files: the time-dependent kinds' common keys
(:func:`femkit.case.transient.setup.transient_schema`, the integrator enum from
:data:`femkit.dynamics.mol.HEAT_INTEGRATORS`) with ``rho_c`` and ``rtol_t`` (adaptive steps).
Every key is described in docs/heat_wave.md."""

from __future__ import annotations

__all__ = ["heat_schema"]


def heat_schema() -> dict:
    """The schema, its enums derived from the registries now."""
    from ...dynamics.mol import HEAT_INTEGRATORS
    from ..transient.setup import transient_schema

    return transient_schema("heat", "rho_c", HEAT_INTEGRATORS, {
        "rtol_t": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1}})
