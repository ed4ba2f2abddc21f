"""The run spec of a ``heat_work_precision`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ...errors import CaseFileError
from ..spec import StudySpec, load_base_case, plain

__all__ = ["HeatStudySpec", "prepare"]


def prepare(study) -> None:
    """Build ``study.spec``; the base case must be a heat case with ``exact`` on a generated mesh."""
    study.spec = HeatStudySpec.from_data(study.data)
    path, case = load_base_case(study)
    if case.problem != "heat" or "exact.u" not in case.functions or case.spec.mesh.geometry is None:
        raise CaseFileError(f"base_case: {path.name} must be a heat case (problem: heat) with an "
                            "exact solution on a generated mesh (mesh.geometry)")
    study.files.append(path)


@dataclass(frozen=True)
class HeatStudySpec(StudySpec):
    """``kind: heat_work_precision`` (defaults: :func:`.schema.schema`)."""

    base_case: str
    schemes: tuple
    h: tuple
    dt: tuple
    case_overrides: Mapping

    @classmethod
    def from_data(cls, d: Mapping) -> "HeatStudySpec":
        if "h" not in d or "dt" not in d:
            raise CaseFileError("give 'h' (mesh sizes) and 'dt' (time steps) to sweep")
        return cls(**cls.common(d), base_case=str(d["base_case"]),
                   schemes=tuple(d["schemes"]), h=tuple(float(v) for v in d["h"]),
                   dt=tuple(float(v) for v in d["dt"]),
                   case_overrides=plain(d.get("case_overrides") or {}))
