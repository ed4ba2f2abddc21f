"""The run spec of a ``contact_penalty`` study (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ...errors import CaseFileError
from ..spec import StudySpec

__all__ = ["ContactPenaltyStudySpec", "prepare"]


def prepare(study) -> None:
    """Build ``study.spec``; ``t_end`` must cover at least one step, and ipctk must be there."""
    from ...contact.barrier import require_ipctk
    from ...errors import InputError

    study.spec = ContactPenaltyStudySpec.from_data(study.data)
    if study.spec.t_end < study.spec.dt:
        raise CaseFileError(f"t_end: {study.spec.t_end:g} is shorter than one step "
                            f"dt = {study.spec.dt:g}")
    try:
        require_ipctk()
    except InputError as exc:
        raise CaseFileError(str(exc)) from None


@dataclass(frozen=True)
class ContactPenaltyStudySpec(StudySpec):
    """``kind: contact_penalty`` (defaults: :func:`.schema.schema`)."""

    stiffnesses: tuple
    n: int
    height: float
    dt: float
    t_end: float

    @classmethod
    def from_data(cls, d: Mapping) -> "ContactPenaltyStudySpec":
        return cls(**cls.common(d), stiffnesses=tuple(float(k) for k in d["stiffnesses"]),
                   n=int(d["n"]), height=float(d["height"]), dt=float(d["dt"]),
                   t_end=float(d["t_end"]))
