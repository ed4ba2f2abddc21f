"""The keys of a ``cloth_work_precision`` study file (JSON-schema properties)."""

from __future__ import annotations

from ...case.specs import SOLVER_SCHEMA

__all__ = ["schema"]


_POS = {"type": "number", "exclusiveMinimum": 0}
_ITS = {"type": "array", "minItems": 1, "items": {"type": "integer", "minimum": 1}}


def schema() -> dict:
    """The kind's own keys (``kind``, ``title``, ``description``, ``output``, ``repeats`` and
    ``warmup`` are common to every study kind); the family enum is the keys of
    :data:`femkit.dynamics.work_precision.FAMILIES`."""
    from ...dynamics.work_precision import FAMILIES

    return _schema(sorted(FAMILIES))


def _schema(families: list) -> dict:
    return {
    "scenes": {"type": "array", "minItems": 1, "items": {"type": "string"},
               "description": "cloth scene files (relative to the study file)"},
    "system_overrides": {"type": "object", "description": "merged into every scene's system block"},
    "frames": {"type": "integer", "minimum": 1, "default": 30},
    "dt": {**_POS, "description": "frame length (default: each scene's dt)"},
    "linear_solver": {**SOLVER_SCHEMA, "default": {}},  # method: the kind's default_solver
    "methods": {"type": "array", "minItems": 1, "items": {
        "type": "object", "additionalProperties": False, "required": ["family"],
        "properties": {"family": {"enum": families},
                       "iterations": _ITS, "options": {"type": "object"},
                       "linear_solver": {**SOLVER_SCHEMA, "description":
                                         "this family's linear solver (default: the study's)"}}},
        "default": [{"family": "fast_mass_spring", "iterations": [1, 2, 3, 5, 10, 20]},
                    {"family": "chebyshev", "iterations": [3, 5, 10, 20]},
                    {"family": "baraff_witkin"},
                    {"family": "newton", "iterations": [1, 2, 3, 4]}]},
    "reference": {"type": "object", "additionalProperties": False, "default": {}, "properties": {
        "tol": {**_POS, "default": 1e-10},
        "solve": {"enum": ["newton", "local_global"], "default": "newton"},
        "trajectory": {"enum": ["newmark", "rk4"], "default": "newmark"},
        "substeps": {"type": "integer", "minimum": 2, "default": 16}}},
    }
