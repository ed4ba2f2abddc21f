"""The keys of a ``stability`` study file and of one stress case (JSON-schema properties)."""

from __future__ import annotations

from ...solvers.core.defaults import COMPARISON_RTOL
from ..schema import INTEGRATOR, POS, POSINT, SOLVER, obj
from .cases import STRESS_CASES

__all__ = ["schema", "stress_case_schema"]


def stress_case_schema() -> dict:
    """The schema of one stress case; its ``type`` enum is :data:`STRESS_CASES`."""
    return obj({
        "name": {"type": "string"},
        "type": {"enum": STRESS_CASES.names()},
        "values": {"type": "array", "minItems": 1, "items": {"type": "number"},
                   "description": "the swept parameter: contrast, aspect ratio, scale, degeneracy, ..."},
        "n": {"type": "integer", "minimum": 2},
        "dofs": POSINT,
        "mass_ratio": {"type": "array", "items": POS},
        "dt_factors": {"type": "array", "items": POS},
        "t_end": POS,
        "maxiter": POSINT,
        "description": {"type": "string"},
    }, required=["type"])


def schema() -> dict:
    """The ``stability`` kind's own keys."""
    return {
        "cases": {"type": "array", "minItems": 1,
                  "items": {"oneOf": [{"type": "string"}, stress_case_schema()],
                            "x-message": "must be a stress case file path or an inline stress case"}},
        "solvers": {"type": "array", "items": SOLVER, "minItems": 1,
                    "default": [{"method": "pcg", "preconditioner": "amg_sa", "rtol": COMPARISON_RTOL},
                                {"method": "pcg", "preconditioner": "amg_rs", "rtol": COMPARISON_RTOL},
                                {"method": "pcg", "preconditioner": "jacobi", "rtol": COMPARISON_RTOL},
                                {"method": "cg", "rtol": COMPARISON_RTOL}]},
        "integrators": {"type": "array", "items": INTEGRATOR, "minItems": 1,
                        "default": ["explicit_euler", "symplectic_euler", "verlet", "rk4"]},
        "case_overrides": {"type": "object", "description": "per case name: keys merged over that case"},
    }
