"""JSON schemas of study files, validated with jsonschema: the keys every study has, the
fragments several kinds use, and :func:`schema_for`, which adds a kind's own keys (its
``schema()``, ``femkit/study/<kind>/schema.py``).

Every object has ``additionalProperties: false``: a misspelled key is an error naming its key
path, the valid keys and the closest match (the machinery of :mod:`femkit.case.schema`).
A ``quick:`` block takes any subset of the kind's own keys and is merged over the file when the
study runs in quick (small) mode: that is how the test suite runs every bundled study small.
"""

from __future__ import annotations

import copy

from ..case.specs import INTEGRATOR_SCHEMA, solver_schema

POS = {"type": "number", "exclusiveMinimum": 0}
POSINT = {"type": "integer", "minimum": 1}


def obj(props: dict, required=(), **extra) -> dict:
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

#: One entry of ``integrators:``: the scene files' integrator spec (a name or {method, options, label}).
INTEGRATOR = INTEGRATOR_SCHEMA


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
    quick = obj({k: copy.deepcopy(v) for k, v in props.items() if k != "kind"})
    for v in quick["properties"].values():
        _partial(v)
    props["quick"] = quick
    return obj(props, required=["kind"])

