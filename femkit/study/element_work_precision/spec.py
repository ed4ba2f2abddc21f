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
    solution with its gradient) and set ``study.spec``."""
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
    problem = study_problem(study)  # the problem's keys, names and expressions are checked now
    if "exact.grad[0]" not in problem.case.functions:
        raise CaseFileError("the problem gives no exact.grad; the H1 errors of the study need it")


@dataclass(frozen=True)
class ElementStudySpec(StudySpec, PoissonSource):
    """``kind: element_work_precision``."""

    h0: float
    counts: tuple          # refinement levels per element
    elements: tuple
    solver: Mapping
    error_order: int

    @classmethod
    def from_data(cls, d: Mapping) -> "ElementStudySpec":
        elements = tuple(d["elements"])
        count = int(d["levels"]["count"])
        counts = d.get("counts") or [max(count - i, 2) for i in range(len(elements))]
        return cls(**cls.common(d), **cls.source(d), h0=float(d["levels"]["h0"]),
                   counts=tuple(int(c) for c in counts), elements=elements,
                   solver=plain(d["solver"]), error_order=int(d["error_order"]))

    @property
    def mesh_h(self) -> float:
        """The ``h`` an inline problem's generated mesh gets."""
        return self.h0
