"""The run spec of a ``stability`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ...errors import CaseFileError
from ..spec import StudySpec, plain

__all__ = ["StabilityStudySpec", "prepare"]


def prepare(study) -> None:
    """Check that every stress case file exists (it joins the fingerprint) and set ``study.spec``."""
    for i, c in enumerate(study.data["cases"]):
        if isinstance(c, str):
            p = study.resolve(c)
            if not p.is_file():
                raise CaseFileError(f"cases[{i}]: stress case file not found: {p}")
            study.files.append(p)
    study.spec = StabilityStudySpec.from_data(study.data)


@dataclass(frozen=True)
class StabilityStudySpec(StudySpec):
    """``kind: stability``: the stress cases, each a file path or an inline mapping, and the
    per-name overrides merged over them."""

    cases: tuple
    case_overrides: Mapping

    @classmethod
    def from_data(cls, d: Mapping) -> "StabilityStudySpec":
        return cls(**cls.common(d), cases=plain(d["cases"]),
                   case_overrides=plain(d.get("case_overrides") or {}))
