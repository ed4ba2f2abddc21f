"""The keys of an ``element_work_precision`` study file (JSON-schema properties)."""

from __future__ import annotations

from ..problem import SOURCE_SCHEMA
from ..schema import POS, POSINT, SOLVER, obj

__all__ = ["schema"]

_NUMBER = {"type": "number"}


def schema() -> dict:
    """The kind's own keys: the problem, the mesh levels (per element), the elements, the solver;
    optionally adaptive series (Poisson) or the reference value of a solid case."""
    return {
        **SOURCE_SCHEMA,
        "levels": obj({"h0": POS, "count": {**POSINT, "minimum": 2}}),
        # names checked against femkit.elements.ELEMENTS at load time
        "elements": {"type": "array", "items": {"type": "string", "minLength": 1}, "minItems": 2,
                     "default": ["P1", "P2"]},
        # refinements of the h0 mesh each element runs: count for the first element, one fewer per
        # element after it unless given (P2 on a level has the unknowns of P1 one level finer)
        "counts": {"type": "array", "items": {**POSINT, "minimum": 2}, "minItems": 2},
        "solver": {**SOLVER, "default": {"method": "pcg", "preconditioner": "amg"}},
        "error_order": {**POSINT, "default": 5},
        # Poisson: each listed element also refined adaptively from the h0 mesh (extra series)
        "adaptive": obj({
            "elements": {"type": "array", "items": {"type": "string", "minLength": 1}, "minItems": 1},
            "theta": {**POS, "maximum": 1, "default": 0.5},
            "max_dofs": POSINT,
            "estimator": {"type": "string", "default": "residual"},
        }, required=("elements", "max_dofs")),
        # a solid base case: the error is that of one displacement component at one node
        "reference": obj({"point": {"type": "array", "items": _NUMBER, "minItems": 2, "maxItems": 3},
                          "component": {"type": "integer", "minimum": 0, "maximum": 2},
                          "value": _NUMBER}, required=("point", "component", "value")),
        "case_overrides": {"type": "object", "default": {},
                           "description": "merged into the base case (e.g. material: {nu: 0.3})"},
    }
