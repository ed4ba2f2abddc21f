"""JSON schema (Draft 2020-12) of ``problem: mass_spring`` scene files.

Every object is closed (``additionalProperties: false``), so a misspelled key is an error
with the valid keys listed. The ``system`` mapping is checked per ``type`` (``rope``,
``cloth``, ``mesh``, ``single_spring``) with ``if``/``then`` branches, so the error for a
wrong key names the keys of *that* builder. The ``system.type`` and force ``type`` enums and
their branches are derived from the registries :data:`femkit.case.scene.systems.SYSTEMS` and
:data:`femkit.case.scene.forces.FORCES` each time the schema is built (:func:`scene_schema`). Names of integrators, linear solvers,
preconditioners and mesh geometries are not enumerated here: they are checked against the
live registries at load time (:func:`femkit.case.scene.run.prepare_scene`).

Every property named here appears in docs/scenes.md (a test checks it).
"""

from __future__ import annotations

from ..contact import CONTACT_SCHEMA
from ..specs import INTEGRATOR_SCHEMA, LIMITS_SCHEMA, SOLVER_SCHEMA
from .forces import FORCES
from ..fragments import POS
from .systems import SYSTEMS

__all__ = ["scene_schema", "force_types", "system_types"]

#: A time: a positive number or a constant expression such as "1/60".
_TIME = {"anyOf": [POS, {"type": "string", "minLength": 1}],
         "x-message": "expected a positive number or a constant expression such as '1/60'"}


def system_types() -> dict:
    """system type -> schema of its mapping, from :data:`~femkit.case.scene.systems.SYSTEMS`."""
    return {name: SYSTEMS.get(name).schema for name in SYSTEMS.names()}


def force_types() -> dict:
    """force type -> schema of its mapping (``type`` included), from
    :data:`~femkit.case.scene.forces.FORCES`."""
    out = {}
    for name in FORCES.names():
        schema = FORCES.get(name).schema
        out[name] = {**schema, "properties": {"type": {"const": name}, **schema["properties"]}}
    return out


def _system() -> dict:
    types = system_types()
    return {
        "type": "object",
        "required": ["type"],
        "properties": {"type": {"enum": sorted(types)}},
        "allOf": [{"if": {"properties": {"type": {"const": name}}, "required": ["type"]},
                   "then": schema} for name, schema in types.items()],
    }


def _forces() -> dict:
    types = force_types()
    item = {
        "type": "object",
        "required": ["type"],
        "properties": {"type": {"enum": sorted(types)}},
        "allOf": [{"if": {"properties": {"type": {"const": name}}, "required": ["type"]},
                   "then": {**schema, "required": ["type", *schema["required"]]}}
                  for name, schema in types.items()],
    }

    def mapping_value(name: str, schema: dict) -> dict:
        short = FORCES.get(name).shorthand
        if short is None:
            return schema
        return {"anyOf": [*short["schema"]["anyOf"], schema],
                "x-message": "expected a magnitude, a vector or a mapping"}

    return {
        "anyOf": [
            {"type": "array", "items": item},
            {"type": "object", "additionalProperties": False,
             "properties": {name: mapping_value(name, s) for name, s in types.items()}},
        ],
        "default": [],
        "x-message": "expected a list of {type: ..., ...} or a mapping force name -> parameters",
    }


def scene_schema() -> dict:
    """The whole scene schema, its force and system branches derived from the registries now
    (so a force or system type registered later is accepted)."""
    return {**_SCENE, "properties": {**_SCENE["properties"], "system": _system(),
                                     "forces": _forces()}}


_SCENE: dict = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "femkit mass-spring scene",
    "type": "object",
    "additionalProperties": False,
    "required": ["problem", "system", "integrator", "dt", "t_end"],
    "properties": {
        "problem": {"const": "mass_spring"},
        "name": {"type": "string", "minLength": 1},
        "description": {"type": "string"},
        "constants": {"type": "object",
                      "propertyNames": {"pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
                      "additionalProperties": {"type": "number"}, "default": {}},
        "integrator": INTEGRATOR_SCHEMA,
        "linear_solver": {**SOLVER_SCHEMA, "default": {}},
        "limits": LIMITS_SCHEMA,
        "contact": CONTACT_SCHEMA,
        "dt": _TIME,
        "t_end": _TIME,
        "stability": {
            "type": "object", "additionalProperties": False, "default": {},
            "properties": {
                "check": {"type": "boolean", "default": True},
                "energy_growth_limit": {"type": "number", "exclusiveMinimum": 0,
                                        "default": 100.0},
                "check_every": {"type": "integer", "minimum": 1, "default": 10},
            },
        },
        "output": {
            "type": "object", "additionalProperties": False, "default": {},
            "properties": {
                "dir": {"type": "string", "minLength": 1},
                "every": {"type": "integer", "minimum": 1},
                "interval": POS,
                "frames": {"type": "integer", "minimum": 1, "default": 100},
                "vtu": {"type": "boolean", "default": True},
                "xdmf": {"type": "boolean", "default": False},
                "energy_csv": {"type": "boolean", "default": True},
                "png": {"type": "boolean", "default": False},
                "gif": {"type": "boolean", "default": False},
            },
        },
    },
}


def __getattr__(name):  # the schema as of now, under its earlier names
    if name == "SCENE_SCHEMA":
        return scene_schema()
    if name == "FORCE_TYPES":
        return force_types()
    if name == "SYSTEM_TYPES":
        return system_types()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
