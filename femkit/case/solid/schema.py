"""JSON schema (Draft 2020-12) of ``problem: solid`` case files.

Closed objects throughout (a misspelt key lists the valid ones). The enums -- material
``model``, mesh ``geometry``, ``element`` and ``integrator`` method -- are derived from their
registries (:data:`femkit.solids.MATERIALS`, :data:`femkit.mesh.GEOMETRIES`,
:data:`femkit.elements.ELEMENTS`, :data:`femkit.dynamics.integrators.INTEGRATORS`) each time the schema is built
(:func:`solid_schema`), so a material, geometry or integrator registered later is accepted.
Value ranges of the material constants (``E > 0``, ``-1 < nu < 1/2``, ``density > 0``) are
checked by the material itself (:func:`femkit.solids.materials.material_from_spec`), whose
messages name the constant. Every property is described in docs/solids.md.
"""

from __future__ import annotations

from ..contact import CONTACT_SCHEMA
from ..fragments import POS, closed
from ..specs import LIMITS_SCHEMA, SOLVER_SCHEMA

__all__ = ["solid_schema", "BOUNDARY_TYPES", "COMPONENTS"]

#: Component names of ``fix:`` (rollers, symmetry planes).
COMPONENTS = ("x", "y", "z")

#: Boundary condition types -> their keys beyond ``tag`` and ``type``.
BOUNDARY_TYPES = ("fixed", "roller", "traction")

_NUM = {"type": "number"}
_VEC = {"type": "array", "minItems": 2, "maxItems": 3, "items": _NUM}
_TIME = {"anyOf": [POS, {"type": "string", "minLength": 1}],
         "x-message": "expected a positive number or a constant expression such as '1/60'"}
_TAG = {"anyOf": [{"type": "string", "minLength": 1}, {"type": "integer"}],
        "x-message": "expected a tag name or number"}
_FIX = {"type": "array", "minItems": 1, "maxItems": 3, "uniqueItems": True,
        "items": {"enum": list(COMPONENTS)}}


def _material() -> dict:
    from ...solids.materials import MATERIALS

    model = closed({"model": {"enum": MATERIALS.names()}, "E": _NUM, "nu": _NUM, "mu": _NUM,
                    "lam": _NUM, "density": _NUM}, ["model"])
    text = {"type": ["string", "number"]}
    energy = closed({"energy": {"anyOf": [{"type": "string", "minLength": 1},
                                          closed({"W": text, "f": text, "g": text, "h": text}, [])]},
                     "constants": {"type": "object", "additionalProperties": _NUM},
                     "density": _NUM}, ["energy"])
    return {"anyOf": [model, energy],
            "x-message": "expected {model: name, E: .., nu: .. (or mu, lam), density: ..} or a "
                         "material designed by its energy {energy: {f: .., g: .., h: ..} or "
                         "{W: ..}, constants: {..}, density: ..}"}


def _integrator() -> dict:
    from ...dynamics.integrators import INTEGRATORS

    names = {"enum": INTEGRATORS.names()}
    return {"anyOf": [names, closed({"method": names, "options": {"type": "object"}}, ["method"])],
            "x-message": f"expected an integrator name ({', '.join(INTEGRATORS.names())}) or "
                         "{method: name, options: {...}}"}


def _mesh() -> dict:
    from ...mesh.geometries import GEOMETRIES

    return {**closed({"geometry": {"enum": GEOMETRIES.names()}, "h": POS,
                      "params": {"type": "object"}, "file": {"type": "string", "minLength": 1}},
                     []),
            "oneOf": [{"required": ["geometry", "h"]}, {"required": ["file"]}],
            "x-message": "give either 'geometry' with 'h' (generated mesh) or 'file' (a .msh "
                         "with physical groups), not both"}


def _boundary() -> dict:
    branch = {
        "fixed": closed({"tag": _TAG, "type": {"const": "fixed"}, "fix": _FIX,
                         "displacement": _VEC}, ["tag", "type"]),
        "roller": closed({"tag": _TAG, "type": {"const": "roller"}, "fix": _FIX,
                          "displacement": _VEC}, ["tag", "type", "fix"]),
        "traction": closed({"tag": _TAG, "type": {"const": "traction"}, "traction": _VEC},
                           ["tag", "type", "traction"]),
    }
    return {"type": "object", "required": ["tag", "type"],
            "properties": {"type": {"enum": list(BOUNDARY_TYPES)}},
            "allOf": [{"if": {"properties": {"type": {"const": t}}, "required": ["type"]},
                       "then": s} for t, s in branch.items()]}


def solid_schema() -> dict:
    """The whole schema, its enums read from the registries now."""
    from ...elements import element_names

    material = _material()
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "femkit elastic solid",
        "type": "object",
        "additionalProperties": False,
        "required": ["problem", "mesh", "material"],
        "properties": {
            "problem": {"const": "solid"},
            "name": {"type": "string", "minLength": 1},
            "description": {"type": "string"},
            "constants": {"type": "object", "additionalProperties": _NUM, "default": {}},
            "mesh": _mesh(),
            "element": {"enum": element_names(), "default": "P1"},
            "material": material,
            "regions": {"type": "object", "additionalProperties": material, "default": {}},
            # none for a body in free flight (dynamics); a static run needs a support (prepare)
            "boundaries": {"type": "array", "items": _boundary(), "default": []},
            "gravity": _VEC,
            "static": {"anyOf": [{"type": "boolean"},
                                 closed({"load_steps": {"type": "integer", "minimum": 1},
                                         "project": {"enum": [True, False, "auto"]},
                                         "max_iterations": {"type": "integer", "minimum": 1},
                                         "rtol": {"type": "number", "exclusiveMinimum": 0}},
                                        [])],
                       "x-message": "expected true or {load_steps: N, project: ..., ...}",
                       "default": False},
            "integrator": _integrator(),
            "dt": _TIME,
            "t_end": _TIME,
            "velocity": _VEC,
            "bodies": {"type": "array", "minItems": 1, "items": closed(
                {"mesh": _mesh(), "material": material, "offset": _VEC, "velocity": _VEC},
                ["offset"])},
            "contact": CONTACT_SCHEMA,
            "linear_solver": {**SOLVER_SCHEMA, "default": {}},
            "limits": LIMITS_SCHEMA,
            "output": {
                "type": "object", "additionalProperties": False, "default": {},
                "properties": {
                    "dir": {"type": "string", "minLength": 1},
                    "every": {"type": "integer", "minimum": 1},
                    "frames": {"type": "integer", "minimum": 1, "default": 50},
                    "vtu": {"type": "boolean", "default": True},
                    "png": {"type": "boolean", "default": True},
                    "gif": {"type": "boolean", "default": False},
                },
            },
        },
    }
