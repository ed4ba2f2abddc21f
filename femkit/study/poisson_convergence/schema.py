"""The keys of a ``poisson_convergence`` study file (JSON-schema properties)."""

from __future__ import annotations

from ..problem import SOURCE_SCHEMA
from ..schema import POS, POSINT, SOLVER, obj

__all__ = ["schema"]


def schema() -> dict:
    """The kind's own top-level keys: the problem, the mesh levels, solvers and rules."""
    return {
        **SOURCE_SCHEMA,
        "levels": obj({
            "h0": POS,
            "count": {**POSINT, "minimum": 2},
            "h": {"type": "array", "items": POS, "minItems": 2},
            "max_level": {"type": "integer", "minimum": 1},
        }),
        "solvers": {"type": "array", "items": SOLVER, "minItems": 1,
                    "default": [{"method": "pcg", "preconditioner": "amg"}]},  # rtol: the one default
        "quadrature": {"type": "array", "items": {"type": "string"}, "minItems": 1,
                       "default": ["barycentric"]},
        "error_order": {**POSINT, "default": 5},
        "reference": {"enum": ["none", "scikit-fem"], "default": "none"},
        "stop_at_discretisation_error": obj({"fraction": {**POS, "default": 0.1}}),
    }
