"""The run spec of a ``wave_energy`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ...errors import CaseFileError
from ..spec import StudySpec, load_base_case, plain

__all__ = ["WaveStudySpec", "prepare"]


def prepare(study) -> None:
    """Build ``study.spec``; the base case must be a wave case."""
    study.spec = WaveStudySpec.from_data(study.data)
    path, case = load_base_case(study)
    if case.problem != "wave":
        raise CaseFileError(f"base_case: {path.name} is not a wave case (problem: wave)")
    study.files.append(path)


@dataclass(frozen=True)
class WaveStudySpec(StudySpec):
    """``kind: wave_energy`` (defaults: :func:`.schema.schema`)."""

    base_case: str
    schemes: tuple
    steps: tuple
    case_overrides: Mapping

    @classmethod
    def from_data(cls, d: Mapping) -> "WaveStudySpec":
        if "steps" not in d:
            raise CaseFileError("give 'steps' (the step counts to sweep)")
        return cls(**cls.common(d), base_case=str(d["base_case"]), schemes=tuple(d["schemes"]),
                   steps=tuple(int(v) for v in d["steps"]),
                   case_overrides=plain(d.get("case_overrides") or {}))
