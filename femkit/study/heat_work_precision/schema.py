"""The keys of a ``heat_work_precision`` study file (JSON-schema properties)."""

from __future__ import annotations

__all__ = ["schema"]


def schema() -> dict:
    """The kind's own keys (``schemes`` enum from :data:`femkit.dynamics.mol.HEAT_INTEGRATORS`)."""
    from ...dynamics.mol import HEAT_INTEGRATORS

    positive = {"type": "number", "exclusiveMinimum": 0}
    return {
        "base_case": {"type": "string", "description": "a heat case with an exact solution"},
        "schemes": {"type": "array", "minItems": 1, "uniqueItems": True,
                        "items": {"enum": HEAT_INTEGRATORS.names()},
                        "default": HEAT_INTEGRATORS.names()},
        "h": {"type": "array", "minItems": 1, "maxItems": 4, "items": positive,
              "description": "mesh sizes (mesh.h of the base case), one curve family each"},
        "dt": {"type": "array", "minItems": 2, "items": positive,
               "description": "time steps swept for every integrator and mesh"},
        "case_overrides": {"type": "object", "default": {},
                           "description": "merged into the base case (e.g. mass: lumped)"},
    }
