"""The keys of a ``springs_vs_elements`` study file (JSON-schema properties)."""

from __future__ import annotations

__all__ = ["schema"]


def schema() -> dict:
    """The kind's own keys; the enums come from the registries (scenes, layouts, materials)."""
    from ...case.specs import INTEGRATOR_SCHEMA
    from ...solids import MATERIALS
    from .layouts import SPRING_LAYOUTS
    from .scenes import SVSE_SCENES

    scenes = {name: {"type": "object", "additionalProperties": False,
                     "properties": SVSE_SCENES.get(name).schema} for name in SVSE_SCENES.names()}
    method = {"type": "object", "additionalProperties": False, "required": ["model"],
              "properties": {"model": {"enum": ["springs", "elements"]},
                             "layout": {"enum": SPRING_LAYOUTS.names()},
                             "material": {"enum": MATERIALS.names()},
                             "integrator": INTEGRATOR_SCHEMA,
                             "label": {"type": "string", "minLength": 1}}}
    pos = {"type": "number", "exclusiveMinimum": 0}
    return {
        "material": {"type": "object", "additionalProperties": False, "default": {},
                     "properties": {"E": {**pos, "default": 5.0e5},
                                    "nu": {"type": "number", "exclusiveMinimum": -1,
                                           "exclusiveMaximum": 0.5, "default": 0.4},
                                    "density": {**pos, "default": 1000.0}}},
        "scenes": {"type": "object", "additionalProperties": False, "minProperties": 1,
                   "properties": scenes,
                   "default": {name: {} for name in SVSE_SCENES.names()}},
        "methods": {"type": "array", "items": method, "minItems": 1},
        "reference": {"type": "object", "additionalProperties": False, "default": {},
                      "properties": {"material": {"enum": MATERIALS.names(),
                                                  "default": "stable_neo_hookean"},
                                     "integrator": {**INTEGRATOR_SCHEMA, "default": {
                                         "method": "newton", "options": {"tol": 1.0e-9}}}}},
    }
