"""The typed run specs of the study kinds, built once by the loader (``study.spec``).

Each study kind's ``prepare`` (its load-time check, :mod:`femkit.study.kinds`) ends by building
its frozen record from the validated file, whose defaults the kind's schema filled
(:mod:`femkit.study.schema`, :func:`femkit.study.stability.stability_schema`,
:func:`femkit.study.cloth.cloth_schema`): the sweep, the cost plan and the report read the
record, never ``study.data`` by string keys. Defaults the schema cannot state (the reference
step of a work-precision study: the smallest swept ``dt`` / 16) are computed here, once.
Every spec shares :class:`StudySpec`'s keys (``title``, ``description``, ``output``,
``repeats``, ``warmup``).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, Mapping

__all__ = ["StudySpec", "PoissonSource", "LevelsSpec", "PoissonStudySpec", "AdaptiveStudySpec", "DynamicsScene",
           "DynamicsReference", "DynamicsStudySpec", "StabilityStudySpec", "ClothReference",
           "ClothStudySpec", "SolidLoadStudySpec", "SpringsStudySpec"]


@dataclass(frozen=True)
class StudySpec:
    """The keys every study kind has (defaults: :data:`femkit.study.schema.COMMON`)."""

    title: str | None
    description: str | None
    output: str | None
    repeats: int
    warmup: int

    @classmethod
    def common(cls, d: Mapping) -> dict:
        return dict(title=d.get("title"), description=d.get("description"),
                    output=d.get("output"), repeats=int(d["repeats"]), warmup=int(d["warmup"]))


def _plain(value: Any) -> Any:
    """A read-only copy of a mapping or list of the file (:func:`femkit.case.frozen.freeze`:
    ``dict``/``list`` subclasses, so schemas and writers still accept them)."""
    from ..case.frozen import freeze

    return freeze(value)


# ----------------------------------------------------------------------------- Poisson studies

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
class PoissonSource:
    """Where a Poisson study's problem comes from: an inline case mapping (``problem``) or a
    case file (``base_case``, as written; resolved against the study file)."""

    problem: Mapping | None
    base_case: str | None

    @staticmethod
    def source(d: Mapping) -> dict:
        return dict(problem=_plain(d["problem"]) if "problem" in d else None,
                    base_case=d.get("base_case"))


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


# ----------------------------------------------------------------------------- dynamics studies

@dataclass(frozen=True)
class DynamicsScene:
    """``scene:`` of a work-precision study (defaults: :data:`femkit.study.schema.SCENE`)."""

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


@dataclass(frozen=True)
class StabilityStudySpec(StudySpec):
    """``kind: stability``: the stress cases, each a file path or an inline mapping, and the
    per-name overrides merged over them."""

    cases: tuple
    case_overrides: Mapping

    @classmethod
    def from_data(cls, d: Mapping) -> "StabilityStudySpec":
        return cls(**cls.common(d), cases=_plain(d["cases"]),
                   case_overrides=_plain(d.get("case_overrides") or {}))


@dataclass(frozen=True)
class ClothReference:
    """``reference:`` of the cloth study (defaults: :func:`femkit.study.cloth.cloth_schema`)."""

    tol: float
    solve: str
    trajectory: str
    substeps: int


@dataclass(frozen=True)
class ClothStudySpec(StudySpec):
    """``kind: cloth_work_precision``."""

    scenes: tuple
    system_overrides: Mapping
    frames: int
    dt: float | None
    linear_solver: Any              # SolverSpec
    methods: tuple                  # {family, iterations, options, linear_solver: SolverSpec}
    reference: ClothReference

    @classmethod
    def from_data(cls, d: Mapping, linear_solver, methods) -> "ClothStudySpec":
        ref = d["reference"]
        return cls(**cls.common(d), scenes=tuple(d["scenes"]),
                   system_overrides=_plain(d.get("system_overrides") or {}),
                   frames=int(d["frames"]), dt=None if d.get("dt") is None else float(d["dt"]),
                   linear_solver=linear_solver, methods=_plain(methods),
                   reference=ClothReference(float(ref["tol"]), str(ref["solve"]),
                                            str(ref["trajectory"]), int(ref["substeps"])))


# ----------------------------------------------------------------------------- solid studies

@dataclass(frozen=True)
class SolidLoadStudySpec(StudySpec):
    """``kind: solid_load`` (defaults: :func:`femkit.study.solid_load.solid_load_schema`)."""

    base_case: str
    materials: tuple
    scale: float
    load_steps: int
    case_overrides: Mapping

    @classmethod
    def from_data(cls, d: Mapping) -> "SolidLoadStudySpec":
        return cls(**cls.common(d), base_case=str(d["base_case"]), materials=tuple(d["materials"]),
                   scale=float(d["scale"]), load_steps=int(d["load_steps"]),
                   case_overrides=_plain(d.get("case_overrides") or {}))


@dataclass(frozen=True)
class SpringsStudySpec(StudySpec):
    """``kind: springs_vs_elements`` (defaults: :func:`femkit.study.springs_elements.
    springs_schema`): the material, each scene's parameters (defaults of its
    :data:`~femkit.study.springs_scenes.SVSE_SCENES` entry filled), the methods
    (:class:`~femkit.study.springs_runs.MethodSpec`) and the reference method."""

    material: Mapping
    scenes: Mapping                 # scene name -> its parameters
    methods: tuple
    reference: Any

    @classmethod
    def from_data(cls, d: Mapping, methods, reference) -> "SpringsStudySpec":
        return cls(**cls.common(d), material=_plain(d["material"]),
                   scenes=_plain({k: dict(v) for k, v in d["scenes"].items()}),
                   methods=tuple(methods), reference=reference)
