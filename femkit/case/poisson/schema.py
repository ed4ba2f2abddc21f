"""JSON schema (Draft 2020-12) of ``problem: poisson`` case files.

Every key is documented in docs/case-files.md (a test checks that each property named here
appears there). Names of geometries, solvers, preconditioners and quadrature rules are not
enumerated here: they are checked against the live registries at load time, so a newly
registered solver is accepted without touching the schema.
"""

from __future__ import annotations

from ..specs import SOLVER_SCHEMA, LIMITS_SCHEMA

_NUMBER_OR_EXPR = {
    "anyOf": [{"type": "number"}, {"type": "string", "minLength": 1}],
    "x-message": "expected a number or an expression string of x and y",
}

_TAGS = {
    "type": "array", "minItems": 1,
    "items": {"anyOf": [{"type": "string", "minLength": 1}, {"type": "integer"}],
              "x-message": "expected a tag name or number"},
}

_MESH = {
    "type": "object",
    "additionalProperties": False,
    "properties": {
        "geometry": {"type": "string", "minLength": 1},
        "h": {"type": "number", "exclusiveMinimum": 0},
        "params": {"type": "object"},
        "file": {"type": "string", "minLength": 1},
        "refine": {"type": "integer", "minimum": 0, "maximum": 8, "default": 0},
    },
    "oneOf": [{"required": ["geometry", "h"]}, {"required": ["file"]}],
    "x-message": "give either 'geometry' with 'h' (generated mesh) or 'file' (read mesh), "
                 "not both",
}

_COEFFICIENT = {
    "anyOf": [
        {"type": "number", "exclusiveMinimum": 0},
        {"type": "string", "minLength": 1},
        {"type": "object", "additionalProperties": False, "required": ["regions"],
         "properties": {
             "regions": {"type": "object", "minProperties": 1,
                         "additionalProperties": {"type": "number", "exclusiveMinimum": 0}},
             "default": {"type": "number", "exclusiveMinimum": 0},
         }},
    ],
    "default": 1.0,
    "x-message": "expected a positive number, an expression string, or "
                 "{regions: {name: value}, default: value}",
}

_POSITIVE = {"type": "number", "exclusiveMinimum": 0}

_ADAPTIVE = {
    "type": "object",
    "additionalProperties": False,
    "properties": {
        "target": _POSITIVE,
        "theta": {"type": "number", "exclusiveMinimum": 0, "maximum": 1, "default": 0.5},
        "max_dofs": {"type": "integer", "exclusiveMinimum": 0},
        "max_time": _POSITIVE,
        "max_levels": {"type": "integer", "exclusiveMinimum": 0, "default": 30},
    },
    "anyOf": [{"required": ["target"]}, {"required": ["max_dofs"]}, {"required": ["max_time"]}],
    "x-prefer-deeper": False,
    "x-message": "give at least one of target, max_dofs, max_time",
}

POISSON_SCHEMA: dict = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "femkit Poisson case: -div(kappa grad u) = f",
    "type": "object",
    "additionalProperties": False,
    "required": ["problem", "mesh", "boundary"],
    "properties": {
        "problem": {"const": "poisson"},
        "name": {"type": "string", "minLength": 1},
        "description": {"type": "string"},
        "constants": {"type": "object",
                      "propertyNames": {"pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
                      "additionalProperties": {"type": "number"}, "default": {}},
        "mesh": _MESH,
        "coefficient": _COEFFICIENT,
        "source": {**_NUMBER_OR_EXPR, "default": 0.0},
        "boundary": {
            "type": "object",
            "additionalProperties": False,
            "properties": {
                "dirichlet": {
                    "type": "array", "minItems": 1,
                    "items": {"type": "object", "additionalProperties": False,
                              "required": ["tags"],
                              "properties": {"tags": _TAGS,
                                             "value": {**_NUMBER_OR_EXPR, "default": 0.0}}},
                },
                "neumann": {
                    "type": "array", "default": [],
                    "items": {"type": "object", "additionalProperties": False,
                              "required": ["tags", "flux"],
                              "properties": {"tags": _TAGS, "flux": _NUMBER_OR_EXPR}},
                },
                # pure Neumann only (no dirichlet): filled at load time (mean_zero, 1e-3)
                "nullspace": {"enum": ["mean_zero", "pin", "error"]},
                "compatibility_rtol": {"type": "number", "exclusiveMinimum": 0,
                                       "exclusiveMaximum": 1},
            },
        },
        "exact": {
            "type": "object",
            "additionalProperties": False,
            "required": ["u"],
            "properties": {
                "u": _NUMBER_OR_EXPR,
                "grad": {"type": "array", "minItems": 2, "maxItems": 3, "items": _NUMBER_OR_EXPR},
            },
        },
        # error estimator of result.json and of adaptive refinement (checked against the
        # femkit.fem.estimators registry at load time)
        "estimator": {"type": "string", "minLength": 1, "default": "residual"},
        # finite element (checked against femkit.elements.ELEMENTS at load time)
        "element": {"type": "string", "minLength": 1, "default": "P1"},
        "adaptive": _ADAPTIVE,
        "quadrature": {
            "type": "object", "additionalProperties": False, "default": {},
            "properties": {"load": {"type": "string", "default": "barycentric"}},
        },
        "solver": {**SOLVER_SCHEMA, "default": {}},
        "limits": LIMITS_SCHEMA,
        "output": {
            "type": "object", "additionalProperties": False, "default": {},
            "properties": {
                "dir": {"type": "string", "minLength": 1},
                "vtu": {"type": "boolean", "default": True},
                "xdmf": {"type": "boolean", "default": False},
                "plot": {"type": "boolean", "default": False},
                # compression of solution.vtu's arrays (femkit.mesh.vtk.COMPRESSIONS)
                "compression": {"enum": ["none", "zlib", "lzma"]},  # unset: none
                "gather_limit": {"type": "integer", "minimum": 0},
            },
        },
    },
}
