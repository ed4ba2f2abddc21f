"""The keys of a ``wave_energy`` study file (JSON-schema properties)."""

from __future__ import annotations

__all__ = ["schema"]


def schema() -> dict:
    """The kind's own keys (``schemes`` enum from :data:`femkit.dynamics.mol.WAVE_INTEGRATORS`)."""
    from ...dynamics.mol import WAVE_INTEGRATORS

    return {
        "base_case": {"type": "string", "description": "a wave case (problem: wave)"},
        "schemes": {"type": "array", "minItems": 1, "uniqueItems": True,
                    "items": {"enum": WAVE_INTEGRATORS.names()},
                    "default": WAVE_INTEGRATORS.names()},
        "steps": {"type": "array", "minItems": 2,
                  "items": {"type": "integer", "minimum": 1},
                  "description": "step counts over the base case's t_end"},
        "case_overrides": {"type": "object", "default": {},
                           "description": "merged into the base case (e.g. mass: lumped)"},
    }
