"""The run spec of a ``solid_load`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ...errors import CaseFileError
from ..spec import StudySpec, plain

__all__ = ["SolidLoadStudySpec", "prepare", "base_case", "tip_traction"]


def base_case(study):
    """``(path, case)`` of the study's base case, ``case_overrides`` merged."""
    from ...case import load_case

    d = study.spec
    path = study.resolve(d.base_case)
    if not path.is_file():
        raise CaseFileError(f"base_case: file not found: {path}")
    return path, load_case(path, **dict(d.case_overrides))


def tip_traction(case) -> tuple:
    """The one traction boundary of a static cantilever case (CaseFileError otherwise)."""
    tractions = [b for b in case.spec.boundaries if b.kind == "traction"]
    if len(tractions) != 1 or case.spec.static is None or case.spec.mesh.get("geometry") != "beam":
        raise CaseFileError("base_case: needs a static solid case on the 'beam' geometry with one "
                            "traction boundary (the loaded tip)")
    return tractions[0]


def prepare(study) -> None:
    """Build ``study.spec`` (:class:`SolidLoadStudySpec`), load the base case
    now (its own checks), and check it is a loaded cantilever."""
    study.spec = SolidLoadStudySpec.from_data(study.data)
    path, case = base_case(study)
    if case.problem != "solid":
        raise CaseFileError(f"base_case: {path.name} is not a solid case (problem: solid)")
    tip_traction(case)
    study.files.append(path)


@dataclass(frozen=True)
class SolidLoadStudySpec(StudySpec):
    """``kind: solid_load`` (defaults: :func:`.schema.schema`)."""

    base_case: str
    materials: tuple
    scale: float
    load_steps: int
    case_overrides: Mapping

    @classmethod
    def from_data(cls, d: Mapping) -> "SolidLoadStudySpec":
        return cls(**cls.common(d), base_case=str(d["base_case"]), materials=tuple(d["materials"]),
                   scale=float(d["scale"]), load_steps=int(d["load_steps"]),
                   case_overrides=plain(d.get("case_overrides") or {}))
