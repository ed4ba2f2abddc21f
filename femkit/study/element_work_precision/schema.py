"""The keys of an ``element_work_precision`` study file (JSON-schema properties)."""

from __future__ import annotations

from ..problem import SOURCE_SCHEMA
from ..schema import POS, POSINT, SOLVER, obj

__all__ = ["schema"]


def schema() -> dict:
    """The kind's own keys: the problem, the mesh levels (per element), the elements, the solver."""
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
    }
