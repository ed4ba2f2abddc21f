"""JSON schemas of study files (one per ``kind``), validated with jsonschema.

Every object has ``additionalProperties: false``: a misspelled key is an error naming its key
path, the valid keys and the closest match (the machinery of :mod:`femkit.case.schema`).
A ``quick:`` block takes any subset of the kind's own keys and is merged over the file when the
study runs in quick (small) mode: that is how the test suite runs every bundled study small.
"""

from __future__ import annotations

import copy

from ..case.specs import INTEGRATOR_SCHEMA, solver_schema
from ..solvers.core.defaults import COMPARISON_RTOL

POS = {"type": "number", "exclusiveMinimum": 0}
POSINT = {"type": "integer", "minimum": 1}


def _obj(props: dict, required=(), **extra) -> dict:
    d = {"type": "object", "additionalProperties": False, "properties": props}
    if required:
        d["required"] = list(required)
    d.update(extra)
    return d


COMMON = {
    "kind": {"type": "string"},
    "title": {"type": "string"},
    "description": {"type": "string"},
    "output": {"type": "string", "description": "report directory (relative to the study file)"},
    "repeats": {**POSINT, "default": 1, "description": "timed repetitions; the minimum is reported"},
    "warmup": {"type": "integer", "minimum": 0, "default": 1, "description": "untimed warm-up runs"},
}

#: One entry of ``solvers:``: femkit's one solver spec (docs/case-files.md#solver) plus a label.
SOLVER = {**solver_schema(label=True), "required": ["method"]}

#: An inline Poisson problem: a case mapping in the case-file language (docs/case-files.md),
#: validated by the Poisson case schema; ``mesh.h`` may be left out (the levels give it).
PROBLEM = {"type": "object", "x-message": "expected a Poisson case mapping (mesh, source, boundary, exact)"}

POISSON = {
    "problem": PROBLEM,
    "base_case": {"type": "string"},
    "levels": _obj({
        "h0": POS,
        "count": {**POSINT, "minimum": 2},
        "h": {"type": "array", "items": POS, "minItems": 2},
        "max_level": {"type": "integer", "minimum": 1},
    }),
    "solvers": {"type": "array", "items": SOLVER, "minItems": 1,
                "default": [{"method": "pcg", "preconditioner": "amg"}]},  # rtol: the one default
    "quadrature": {"type": "array", "items": {"type": "string"}, "minItems": 1, "default": ["barycentric"]},
    "error_order": {**POSINT, "default": 5},
    "reference": {"enum": ["none", "scikit-fem"], "default": "none"},
    "stop_at_discretisation_error": _obj({"fraction": {**POS, "default": 0.1}}),
}

ADAPTIVE = {
    "problem": PROBLEM,
    "base_case": {"type": "string"},
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

SCENE = _obj({
    "type": {"enum": ["harmonic_oscillator", "single_spring", "rope"]},
    "k": {**POS, "default": 100.0},
    "mass": {**POS, "default": 1.0},
    "amplitude": {**POS, "default": 0.1},
    "rest": {**POS, "default": 1.0},
    "n": {"type": "integer", "minimum": 2, "default": 8},
    "gravity": {"type": "number", "default": 0.0},
    "t_end": {**POS, "default": 1.0},
}, required=["type"])

#: One entry of ``integrators:``: the scene files' integrator spec (a name or {method, options, label}).
INTEGRATOR = INTEGRATOR_SCHEMA

DYNAMICS = {
    "scene": SCENE,
    "integrators": {"type": "array", "items": INTEGRATOR, "minItems": 1},
    "dt": _obj({"k_min": {"type": "integer"}, "k_max": {"type": "integer"},
                "values": {"type": "array", "items": POS, "minItems": 2}}),
    "reference": _obj({"integrator": {"type": "string", "default": "rk4"},
                       "dt": {**POS, "description": "default: the smallest swept dt / 16"},
                       "analytic": {"type": "boolean", "default": True}}, default={}),
    "energy_growth_limit": {**POS, "default": 10.0},
}

def _partial(node: dict) -> None:
    """A ``quick:`` value may give part of an object: no defaults, no required keys (lists stay whole)."""
    node.pop("default", None)
    node.pop("required", None)
    for v in (node.get("properties") or {}).values():
        _partial(v)


def schema_for(kind: str) -> dict:
    """The full schema of a study of ``kind`` (with its ``quick:`` block)."""
    from ..kinds import KINDS

    props = {**copy.deepcopy(COMMON), **copy.deepcopy(KINDS.get(kind, "kind").get_schema())}
    quick = _obj({k: copy.deepcopy(v) for k, v in props.items() if k != "kind"})
    for v in quick["properties"].values():
        _partial(v)
    props["quick"] = quick
    return _obj(props, required=["kind"])

