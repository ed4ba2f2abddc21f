"""The run spec of an ``adaptive`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ...errors import CaseFileError
from ..checks import check_base_case, check_nested, check_problem_source
from ..problem import PoissonSource, study_problem
from ..spec import StudySpec

__all__ = ["AdaptiveStudySpec", "prepare"]


def prepare(study) -> None:
    """Check what the schema cannot (one problem source, ``max_dofs``, the estimators and the
    loop's settings, the case, no multigrid on graded meshes) and set ``study.spec``."""
    from ...case.name_checks import lookup
    from ...fem.adaptive import check_settings
    from ...fem.estimators import ESTIMATORS

    d = study.data
    check_problem_source(study, "adaptive")
    if "max_dofs" not in d:
        raise CaseFileError("(top level): missing required key 'max_dofs' (the budget of both refinements)")
    for i, name in enumerate(d["estimators"]):
        lookup(ESTIMATORS, name, f"estimators[{i}]")
    check_settings(theta=d["theta"], target=d.get("target"), max_dofs=d["max_dofs"],
                   max_time=d.get("max_time"), max_levels=d["max_levels"])
    study.spec = AdaptiveStudySpec.from_data(d)
    check_base_case(study)
    study_problem(study, need_exact=False)
    check_nested(study, True, "adaptive refinement makes graded meshes, not uniformly refined "
                 "nested ones")


@dataclass(frozen=True)
class AdaptiveStudySpec(StudySpec, PoissonSource):
    """``kind: adaptive``."""

    h0: float | None
    estimators: tuple
    theta: float
    target: float | None
    max_dofs: int
    max_time: float | None
    max_levels: int
    fit_min_dofs: int

    @classmethod
    def from_data(cls, d: Mapping) -> "AdaptiveStudySpec":
        return cls(**cls.common(d), **cls.source(d), h0=d.get("h0"), estimators=tuple(d["estimators"]),
                   theta=float(d["theta"]), target=d.get("target"), max_dofs=int(d["max_dofs"]),
                   max_time=d.get("max_time"), max_levels=int(d["max_levels"]),
                   fit_min_dofs=int(d["fit_min_dofs"]))

    @property
    def mesh_h(self) -> float | None:
        """The ``h`` an inline problem's generated mesh gets (``h0``)."""
        return self.h0

    def runs(self) -> list[tuple[str, str, str]]:
        """(label, refinement, estimator): uniform first (estimated with the first estimator)."""
        ests = self.estimators
        return [("uniform", "uniform", ests[0])] + [(f"adaptive ({e})", "adaptive", e) for e in ests]
