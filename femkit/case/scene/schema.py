"""JSON schema (Draft 2020-12) of ``problem: mass_spring`` scene files.

Every object is closed (``additionalProperties: false``), so a misspelled key is an error
with the valid keys listed. The ``system`` mapping is checked per ``type`` (``rope``,
``cloth``, ``mesh``, ``single_spring``) with ``if``/``then`` branches, so the error for a
wrong key names the keys of *that* builder. Names of integrators, linear solvers,
preconditioners and mesh geometries are not enumerated here: they are checked against the
live registries at load time (:func:`femkit.case.scene.run.prepare_scene`).

Every property named here appears in docs/scenes.md (a test checks it).
"""

from __future__ import annotations

from ..specs import INTEGRATOR_SCHEMA, SOLVER_SCHEMA

_POS = {"type": "number", "exclusiveMinimum": 0}
_NONNEG = {"type": "number", "minimum": 0}
_COUNT2 = {"type": "integer", "minimum": 2}
_VEC = {"type": "array", "minItems": 2, "maxItems": 3, "items": {"type": "number"}}
_DIM = {"enum": [2, 3]}
_NODES = {"type": "array", "items": {"type": "integer", "minimum": 0}}
_DAMPING = _NONNEG
#: A time: a positive number or a constant expression such as "1/60".
_TIME = {"anyOf": [_POS, {"type": "string", "minLength": 1}],
         "x-message": "expected a positive number or a constant expression such as '1/60'"}  # dashpot coefficient along every spring

#: Initial velocity: a constant vector, or one expression string of ``x, y, z`` per component.
_VELOCITY = {
    "type": "array", "minItems": 2, "maxItems": 3,
    "items": {"anyOf": [{"type": "number"}, {"type": "string", "minLength": 1}],
              "x-message": "expected a number or an expression string of x, y, z"},
}


def _pinned(named: list[str]) -> dict:
    return {"anyOf": [{"enum": named}, _NODES],
            "x-message": f"expected one of {', '.join(named)} or a list of node indices"}


def _closed(props: dict, required: list[str]) -> dict:
    return {"type": "object", "additionalProperties": False, "required": required,
            "properties": props}


_COMMON = {"type": {"type": "string"}, "damping": _DAMPING, "velocity": _VELOCITY}

ROPE = _closed({
    **_COMMON,
    "origin": _VEC, "n": _COUNT2, "length": _POS, "k": _POS, "mass": _POS, "total_mass": _POS, "dim": _DIM,
    "pinned": _pinned(["first", "last", "both", "none"]),
}, ["type", "n", "length", "k"])

CLOTH = _closed({
    **_COMMON,
    "origin": _VEC, "nx": _COUNT2, "ny": _COUNT2, "width": _POS, "height": _POS,
    "k_structural": _POS, "k_shear": _NONNEG, "k_bending": _NONNEG,
    "mass": _POS, "total_mass": _POS, "plane": {"enum": ["xz", "xy"]}, "dim": _DIM,
    "pinned": _pinned(["top_corners", "corners", "top_edge", "none"]),
}, ["type", "nx", "ny", "width", "height", "k_structural"])

MESH = {
    **_closed({
        **_COMMON,
        "origin": _VEC, "geometry": {"type": "string", "minLength": 1}, "h": _POS, "params": {"type": "object"},
        "file": {"type": "string", "minLength": 1},
        "k": _POS, "density": _POS, "thickness": _POS, "dim": _DIM,
        "pinned": {"anyOf": [{"type": "string", "minLength": 1}, _NODES],
                   "x-message": "expected a boundary tag name or a list of node indices"},
    }, ["type", "k"]),
    "oneOf": [{"required": ["geometry", "h"]}, {"required": ["file"]}],
    "x-message": "give either 'geometry' with 'h' (generated mesh) or 'file' (read mesh), not both",
}

SINGLE_SPRING = _closed({
    **_COMMON,
    "k": _POS, "m": _POS, "rest": _POS, "dim": _DIM,
}, ["type", "k", "m"])

#: system type -> schema of its mapping
SYSTEM_TYPES = {"rope": ROPE, "cloth": CLOTH, "mesh": MESH, "single_spring": SINGLE_SPRING}

_SYSTEM = {
    "type": "object",
    "required": ["type"],
    "properties": {"type": {"enum": sorted(SYSTEM_TYPES)}},
    "allOf": [{"if": {"properties": {"type": {"const": name}}, "required": ["type"]},
               "then": schema} for name, schema in SYSTEM_TYPES.items()],
}

GRAVITY = _closed({"type": {"const": "gravity"},
                   "g": {"anyOf": [_NONNEG, _VEC],
                         "x-message": "expected a magnitude >= 0 or a vector"},
                   "axis": {"type": "integer"}}, [])
DASHPOT = _closed({"type": {"const": "dashpot"}, "c": _NONNEG}, ["c"])
VISCOUS = _closed({"type": {"const": "viscous"}, "gamma": _NONNEG,
                   "per_mass": {"type": "boolean"}}, ["gamma"])
RAYLEIGH = _closed({"type": {"const": "rayleigh"}, "alpha": _NONNEG, "beta": _NONNEG}, [])
GROUND = _closed({"type": {"const": "ground"}, "height": {"type": "number"},
                  "stiffness": _POS, "normal": _VEC}, ["stiffness"])
SPHERE = _closed({"type": {"const": "sphere"}, "centre": _VEC, "radius": _POS,
                  "stiffness": _POS}, ["centre", "radius", "stiffness"])

#: force type -> schema of its mapping
FORCE_TYPES = {"gravity": GRAVITY, "dashpot": DASHPOT, "viscous": VISCOUS,
               "rayleigh": RAYLEIGH, "ground": GROUND, "sphere": SPHERE}

_FORCE_ITEM = {
    "type": "object",
    "required": ["type"],
    "properties": {"type": {"enum": sorted(FORCE_TYPES)}},
    "allOf": [{"if": {"properties": {"type": {"const": name}}, "required": ["type"]},
               "then": {**schema, "required": ["type", *schema["required"]]}}
              for name, schema in FORCE_TYPES.items()],
}

_FORCES = {
    "anyOf": [
        {"type": "array", "items": _FORCE_ITEM},
        {"type": "object", "additionalProperties": False,
         "properties": {name: ({"anyOf": [_NONNEG, _VEC, s],
                                "x-message": "expected a magnitude, a vector or a mapping"}
                               if name == "gravity" else s)
                        for name, s in FORCE_TYPES.items()}},
    ],
    "default": [],
    "x-message": "expected a list of {type: ..., ...} or a mapping force name -> parameters",
}

SCENE_SCHEMA: dict = {
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
        "system": _SYSTEM,
        "forces": _FORCES,
        "integrator": INTEGRATOR_SCHEMA,
        "linear_solver": {**SOLVER_SCHEMA, "default": {}},
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
                "interval": _POS,
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
