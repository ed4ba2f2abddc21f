"""The run spec of an ``element_work_precision`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ...errors import CaseFileError
from ..checks import check_base_case, check_problem_source
from ..problem import PoissonSource, study_problem
from ..spec import StudySpec, plain

__all__ = ["ElementStudySpec", "prepare"]


def prepare(study) -> None:
    """Check what the schema cannot (one problem source, the levels, element names, an exact
    solution with its gradient, or a solid base case with its ``reference``; the adaptive
    series' elements and estimator) and set ``study.spec``."""
    from ...case.name_checks import lookup
    from ...elements import ELEMENTS

    check_problem_source(study, "element_work_precision")
    d = study.data
    lv = d.get("levels") or {}
    if "h0" not in lv or "count" not in lv:
        raise CaseFileError("levels: give 'h0' and 'count' (uniform refinements of one mesh)")
    for i, name in enumerate(d["elements"]):
        lookup(ELEMENTS, name, f"elements[{i}]")
    if len(set(d["elements"])) != len(d["elements"]):
        raise CaseFileError(f"elements: each element once, got {list(d['elements'])}")
    counts = d.get("counts")
    if counts is not None and len(counts) != len(d["elements"]):
        raise CaseFileError(f"counts: one per element ({len(d['elements'])}), got {len(counts)}")
    study.spec = ElementStudySpec.from_data(d)
    check_base_case(study)
    solid = _solid_case(study)
    if solid is not None:
        if solid.spec.static is None:
            raise CaseFileError("base_case: a solid case must be static (static: true) for this study")
        if d.get("reference") is None:
            raise CaseFileError("reference: a solid base case needs 'reference' {point, component, "
                                "value} (the converged displacement the error is measured against)")
        if d.get("adaptive") is not None:
            raise CaseFileError("adaptive: adaptive series are for Poisson cases only, not a solid base case")
        return
    if d.get("case_overrides"):
        raise CaseFileError("case_overrides: only for a solid base case; give a Poisson case's "
                            "values in its file or inline under 'problem'")
    if d.get("reference") is not None:
        raise CaseFileError("reference: only for a solid base case; a Poisson case is measured "
                            "against its 'exact' solution")
    problem = study_problem(study)  # the problem's keys, names and expressions are checked now
    if "exact.grad[0]" not in problem.case.functions:
        raise CaseFileError("the problem gives no exact.grad; the H1 errors of the study need it")
    _check_adaptive(d.get("adaptive"), lookup, ELEMENTS)


def _solid_case(study):
    """The base case (read with ``case_overrides``) when it is a ``problem: solid`` file, else None."""
    from ..spec import load_base_case

    if study.spec.base_case is None:
        return None
    case = load_base_case(study)[1]
    return case if case.problem == "solid" else None


def _check_adaptive(a, lookup, elements) -> None:
    from ...fem.estimators import ESTIMATORS

    if a is None:
        return
    for i, name in enumerate(a["elements"]):
        lookup(elements, name, f"adaptive.elements[{i}]")
    lookup(ESTIMATORS, a.get("estimator", "residual"), "adaptive.estimator")


@dataclass(frozen=True)
class ElementStudySpec(StudySpec, PoissonSource):
    """``kind: element_work_precision``."""

    h0: float
    counts: tuple          # refinement levels per element
    elements: tuple
    solver: Mapping
    error_order: int
    adaptive: Mapping | None = None      # {elements, theta, max_dofs, estimator}: extra series
    reference: Mapping | None = None     # a solid base case: {point, component, value}
    case_overrides: Mapping | None = None  # solid base case only: merged into it

    @classmethod
    def from_data(cls, d: Mapping) -> "ElementStudySpec":
        elements = tuple(d["elements"])
        count = int(d["levels"]["count"])
        counts = d.get("counts") or [max(count - i, 2) for i in range(len(elements))]
        return cls(**cls.common(d), **cls.source(d), h0=float(d["levels"]["h0"]),
                   counts=tuple(int(c) for c in counts), elements=elements,
                   solver=plain(d["solver"]), error_order=int(d["error_order"]),
                   adaptive=_adaptive(d.get("adaptive")), reference=plain(d.get("reference")),
                   case_overrides=plain(d.get("case_overrides") or {}))

    def series(self) -> tuple:
        """The series' names: the elements (uniform refinement), then ``"<element> adaptive"``."""
        extra = () if self.adaptive is None else tuple(f"{e} adaptive" for e in self.adaptive["elements"])
        return self.elements + extra

    @property
    def mesh_h(self) -> float:
        """The ``h`` an inline problem's generated mesh gets."""
        return self.h0


def _adaptive(a) -> dict | None:
    if a is None:
        return None
    return plain({"elements": list(a["elements"]), "theta": float(a.get("theta", 0.5)),
                  "max_dofs": int(a["max_dofs"]), "estimator": a.get("estimator", "residual")})
