"""The run spec of a ``dynamics_work_precision`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Mapping

from ...errors import CaseFileError
from ..spec import StudySpec

__all__ = ["DynamicsScene", "DynamicsReference", "DynamicsStudySpec", "prepare"]


def prepare(study) -> None:
    """Check the keys the schema cannot require (a scene, integrators and a dt sweep) and set
    ``study.spec``."""
    d = study.data
    for key in ("scene", "integrators", "dt"):
        if key not in d:
            raise CaseFileError(f"(top level): missing required key {key!r}")
    dt = d["dt"]
    if "values" not in dt and not ("k_min" in dt and "k_max" in dt and dt["k_max"] > dt["k_min"]):
        raise CaseFileError("dt: give 'values' or 'k_min' < 'k_max' (dt = 2^-k)")
    study.spec = DynamicsStudySpec.from_data(d)


@dataclass(frozen=True)
class DynamicsScene:
    """``scene:`` of a work-precision study (defaults: :data:`.schema.SCENE`)."""

    type: str
    k: float
    mass: float
    amplitude: float
    rest: float
    n: int
    gravity: float
    t_end: float

    @property
    def size(self) -> tuple[int, int]:
        """``(nodes, springs)`` of the scene's system."""
        return (self.n, self.n - 1) if self.type == "rope" else (2, 1)

    @property
    def analytic(self) -> bool:
        """Whether the scene has a closed-form solution (the oscillator, the single spring)."""
        return self.type != "rope"


@dataclass(frozen=True)
class DynamicsReference:
    """``reference:``: the analytic solution when the scene has one and ``analytic``, else a
    run of ``integrator`` at ``dt`` (default: the smallest swept dt / 16)."""

    integrator: str
    dt: float
    analytic: bool


@dataclass(frozen=True)
class DynamicsStudySpec(StudySpec):
    """``kind: dynamics_work_precision``."""

    scene: DynamicsScene
    dts: tuple                      # the swept steps, largest first
    reference: DynamicsReference
    energy_growth_limit: float

    @classmethod
    def from_data(cls, d: Mapping) -> "DynamicsStudySpec":
        names = {f.name for f in fields(DynamicsScene)}
        scene = DynamicsScene(**{k: v for k, v in d["scene"].items() if k in names})
        dt = d["dt"]
        if "values" in dt:
            dts = tuple(sorted((float(v) for v in dt["values"]), reverse=True))
        else:
            dts = tuple(2.0 ** (-k) for k in range(dt["k_min"], dt["k_max"] + 1))
        ref = d["reference"]  # integrator and analytic filled by the schema
        reference = DynamicsReference(str(ref["integrator"]),
                                      float(ref["dt"]) if "dt" in ref else min(dts) / 16,
                                      bool(ref["analytic"]))
        return cls(**cls.common(d), scene=scene, dts=dts, reference=reference,
                   energy_growth_limit=float(d["energy_growth_limit"]))
