"""The keys of a ``solid_load`` study file (JSON-schema properties)."""

from __future__ import annotations

__all__ = ["schema"]


def schema() -> dict:
    """The kind's own keys (``materials`` enum from :data:`femkit.solids.MATERIALS`)."""
    from ...solids import MATERIALS

    return {
        "base_case": {"type": "string", "description": "a static solid case (beam, tip traction)"},
        "materials": {"type": "array", "minItems": 1, "uniqueItems": True,
                      "items": {"enum": MATERIALS.names()},
                      "default": ["linear", "corotational", "stvk", "stable_neo_hookean"]},
        "scale": {"type": "number", "exclusiveMinimum": 0, "default": 1.0,
                  "description": "multiplies the base case's tractions and gravity"},
        "load_steps": {"type": "integer", "minimum": 1, "default": 10},
        "case_overrides": {"type": "object", "default": {},
                           "description": "merged into the base case (e.g. mesh: {h: 0.5})"},
    }
