"""The keys of a ``dynamics_work_precision`` study file (JSON-schema properties)."""

from __future__ import annotations

from ..schema import INTEGRATOR, POS, obj

__all__ = ["schema", "SCENE"]

#: ``scene:``: a spring scene with (or without) a closed-form solution.
SCENE = obj({
    "type": {"enum": ["harmonic_oscillator", "single_spring", "rope"]},
    "k": {**POS, "default": 100.0},
    "mass": {**POS, "default": 1.0},
    "amplitude": {**POS, "default": 0.1},
    "rest": {**POS, "default": 1.0},
    "n": {"type": "integer", "minimum": 2, "default": 8},
    "gravity": {"type": "number", "default": 0.0},
    "t_end": {**POS, "default": 1.0},
}, required=["type"])


def schema() -> dict:
    """The kind's own top-level keys: the scene, the integrators, the swept steps, the reference."""
    return {
        "scene": SCENE,
        "integrators": {"type": "array", "items": INTEGRATOR, "minItems": 1},
        "dt": obj({"k_min": {"type": "integer"}, "k_max": {"type": "integer"},
                    "values": {"type": "array", "items": POS, "minItems": 2}}),
        "reference": obj({"integrator": {"type": "string", "default": "rk4"},
                           "dt": {**POS, "description": "default: the smallest swept dt / 16"},
                           "analytic": {"type": "boolean", "default": True}}, default={}),
        "energy_growth_limit": {**POS, "default": 10.0},
    }
