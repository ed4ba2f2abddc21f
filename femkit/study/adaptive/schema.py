"""The keys of an ``adaptive`` study file (JSON-schema properties)."""

from __future__ import annotations

from ...solvers.core.defaults import COMPARISON_RTOL
from ..problem import SOURCE_SCHEMA
from ..schema import POS, POSINT, SOLVER

__all__ = ["schema"]


def schema() -> dict:
    """The kind's own top-level keys: the problem, the refinement's settings, one solver."""
    return {
        **SOURCE_SCHEMA,
        "h0": {**POS, "description": "initial mesh size of a generated mesh (default: the case's mesh.h)"},
        "estimators": {"type": "array", "items": {"type": "string"}, "minItems": 1, "default": ["residual"]},
        "theta": {"type": "number", "exclusiveMinimum": 0, "maximum": 1, "default": 0.5},
        "target": POS,
        "max_dofs": {"type": "integer", "exclusiveMinimum": 0},
        "max_time": POS,
        "max_levels": {**POSINT, "default": 40},
        "fit_min_dofs": {**POSINT, "default": 200},
        "solvers": {"type": "array", "items": SOLVER, "minItems": 1, "maxItems": 1,
                    "default": [{"method": "pcg", "preconditioner": "amg", "rtol": COMPARISON_RTOL}]},
    }
