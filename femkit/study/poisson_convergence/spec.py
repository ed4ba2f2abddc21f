"""The run spec of a ``poisson_convergence`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ...errors import CaseFileError
from ..checks import check_base_case, check_nested, check_problem_source
from ..problem import PoissonSource, study_problem
from ..spec import StudySpec

__all__ = ["LevelsSpec", "PoissonStudySpec", "prepare"]


def prepare(study) -> None:
    """Check what the schema cannot (one problem source, the levels, the case's keys, names and
    expressions, multigrid on nested levels only) and set ``study.spec``."""
    check_problem_source(study, "poisson_convergence")
    lv = study.data.get("levels") or {}
    if "h" not in lv and not ("h0" in lv and "count" in lv):
        raise CaseFileError("levels: give either 'h' (a list of mesh sizes) or 'h0' and 'count' "
                            "(uniform refinements of one mesh)")
    study.spec = PoissonStudySpec.from_data(study.data)
    check_base_case(study)
    study_problem(study)  # the problem's keys, names and expressions are checked now
    check_nested(study, "h" in lv, "levels: {h: [...]} gives independent gmsh meshes, not "
                 "nested ones; use levels: {h0, count} (uniform refinements)")


@dataclass(frozen=True)
class LevelsSpec:
    """``levels:`` of a convergence study: gmsh meshes per ``h``, or ``count`` uniform
    refinements of the mesh at ``h0``; ``max_level`` cuts either."""

    h: tuple | None
    h0: float | None
    count: int | None
    max_level: int | None

    @property
    def nested(self) -> bool:
        """Uniform refinements of one mesh (what multigrid and nested iteration need)."""
        return self.h is None

    def sizes(self) -> list[tuple[float, int]]:
        """``(h, refinements)`` of each level, in the order the sweep builds them."""
        if self.h is not None:
            hs = list(self.h) if self.max_level is None else list(self.h)[: self.max_level + 1]
            return [(float(h), 0) for h in hs]
        count = self.count if self.max_level is None else min(self.count, self.max_level + 1)
        return [(float(self.h0), k) for k in range(count)]

    @property
    def first_h(self) -> float:
        return float(self.h[0]) if self.h is not None else float(self.h0)


@dataclass(frozen=True)
class PoissonStudySpec(StudySpec, PoissonSource):
    """``kind: poisson_convergence``."""

    levels: LevelsSpec
    quadrature: tuple
    error_order: int
    reference: str
    stop_fraction: float | None   # stop_at_discretisation_error.fraction (None: no nested runs)

    @classmethod
    def from_data(cls, d: Mapping) -> "PoissonStudySpec":
        lv = d["levels"]
        stop = d.get("stop_at_discretisation_error")
        return cls(**cls.common(d), **cls.source(d),
                   levels=LevelsSpec(tuple(float(h) for h in lv["h"]) if "h" in lv else None,
                                     float(lv["h0"]) if "h0" in lv else None,
                                     int(lv["count"]) if "count" in lv else None,
                                     int(lv["max_level"]) if "max_level" in lv else None),
                   quadrature=tuple(d["quadrature"]), error_order=int(d["error_order"]),
                   reference=str(d["reference"]),
                   stop_fraction=None if stop is None else float(stop["fraction"]))

    @property
    def mesh_h(self) -> float:
        """The ``h`` an inline problem's generated mesh gets (the first level's)."""
        return self.levels.first_h
