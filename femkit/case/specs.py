"""One validated spec per concept, shared by case files, scenes and studies.

A spec is built once, after schema validation, from the mapping a file gives; the names in it
are checked against the live registries (so a newly registered solver is accepted without
touching a schema) and every default comes from one table, :mod:`femkit.solvers.core.defaults`.
The records themselves belong to the library layers (:class:`femkit.solvers.SolverSpec`,
:class:`IntegratorSpec` here); this module adds the schema fragments (:data:`SOLVER_SCHEMA`,
:data:`INTEGRATOR_SCHEMA`), the same objects in every file schema, and :func:`solver_spec`,
which prefixes load-time errors with the key path.

>>> spec = solver_spec({"method": "pcg"}, "solver")
>>> spec.preconditioner, spec.rtol, spec.label
('amg', 1e-10, 'pcg+amg')
>>> solver_spec({"method": "cg", "preconditioner": "ic0"}, "solver")
Traceback (most recent call last):
...
femkit.errors.CaseFileError: solver.preconditioner: preconditioner 'ic0' is only valid with method 'pcg', not 'cg' (use method 'pcg', or no preconditioner)
>>> IntegratorSpec.from_mapping("rk4", "integrator").method
'rk4'
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Mapping

from ..errors import CaseFileError, InputError, UnknownNameError
from ..solvers.spec import SolverSpec
from .name_checks import lookup, with_prefix

__all__ = ["SolverSpec", "IntegratorSpec", "SOLVER_SCHEMA", "INTEGRATOR_SCHEMA", "solver_schema",
           "solver_spec", "LIMITS_SCHEMA", "limits_spec"]


def solver_spec(data: Mapping[str, Any] | None, where: str, *,
                default_method: str = "pcg") -> SolverSpec:
    """:meth:`SolverSpec.from_mapping` for a file: a bad combination is a CaseFileError (exit 2).

    Unknown names stay :class:`~femkit.errors.UnknownNameError`.
    """
    try:
        return SolverSpec.from_mapping(data, where, default_method=default_method)
    except UnknownNameError:
        raise
    except InputError as exc:
        raise CaseFileError(str(exc)) from None


def solver_schema(*, label: bool = False) -> dict:
    """JSON-schema fragment of a solver mapping (defaults are filled by :class:`SolverSpec`)."""
    props = {
        "method": {"type": "string", "minLength": 1},
        "preconditioner": {"type": ["string", "null"]},
        "rtol": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1},
        "atol": {"type": "number", "minimum": 0},
        "maxiter": {"type": ["integer", "null"], "minimum": 1},
        "options": {"type": "object"},
        "preconditioner_options": {"type": "object"},
        "backend": {"type": "string", "minLength": 1},
        "petsc_options": {"type": "object"},
    }
    if label:
        props["label"] = {"type": "string", "minLength": 1}
    return {"type": "object", "additionalProperties": False, "properties": props}


#: The solver fragment of case and scene files (``solver:``, ``linear_solver:``).
SOLVER_SCHEMA: dict = solver_schema()

_SIZE = {"anyOf": [{"type": "number", "exclusiveMinimum": 0}, {"type": "string", "minLength": 1}],
         "x-message": "expected a positive number or a string with a unit, like 2GiB or 10min"}

#: The budget fragment of case and scene files (``limits:``): memory and output in bytes
#: (``2GiB``, ``500MB``), time in seconds (``10min``, ``2h``), steps a count.
LIMITS_SCHEMA: dict = {
    "type": "object", "additionalProperties": False,
    "properties": {"memory": _SIZE, "time": _SIZE, "output": _SIZE,
                   "steps": {"type": "number", "exclusiveMinimum": 0}},
}


def limits_spec(data: Mapping[str, Any] | None, where: str = "limits"):
    """The :class:`femkit.cost.Limits` of a ``limits:`` mapping; a bad size is a CaseFileError."""
    from ..cost import Limits

    try:
        return Limits.from_mapping(data, where)
    except InputError as exc:
        raise CaseFileError(str(exc)) from None


#: The integrator fragment: a name, or ``{method: name, options: {...}}``.
INTEGRATOR_SCHEMA: dict = {
    "anyOf": [
        {"type": "string", "minLength": 1},
        {"type": "object", "additionalProperties": False, "required": ["method"],
         "properties": {"method": {"type": "string", "minLength": 1},
                        "options": {"type": "object"},
                        "label": {"type": "string", "minLength": 1}}},
    ],
    "x-message": "expected an integrator name or {method: name, options: {...}}",
}


@dataclass(frozen=True)
class IntegratorSpec:
    """An integrator by name with its options (``integrator:`` in scenes, ``integrators:`` in
    studies); ``label`` names it in reports (default: the name, then ``key=value`` options)."""

    method: str
    options: dict = field(default_factory=dict)
    label: str = ""

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any] | str, where: str) -> "IntegratorSpec":
        """Accept ``"rk4"`` or ``{method: rk4, options: {...}}``; check the name and options now."""
        from ..dynamics.integrators import INTEGRATORS, get_integrator

        d = {"method": data} if isinstance(data, str) else dict(data)
        lookup(INTEGRATORS, d["method"], f"{where}.method")
        options = dict(d.get("options") or {})
        try:
            get_integrator(d["method"], **options)
        except InputError as exc:
            raise with_prefix(exc, f"{where}.options") from None
        label = d.get("label") or (d["method"] + ("" if not options else " " + ",".join(
            f"{k}={v}" for k, v in options.items())))
        return cls(d["method"], options, label)

    def build(self):
        """A fresh integrator object."""
        from ..dynamics.integrators import get_integrator

        return get_integrator(self.method, **self.options)

    def to_dict(self) -> dict:
        return asdict(self)
