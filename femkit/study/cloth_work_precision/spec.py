"""The run spec of a ``cloth_work_precision`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from ...errors import CaseFileError, InputError
from ...kinds import KINDS
from ..spec import StudySpec, plain

__all__ = ["ClothReference", "ClothStudySpec", "prepare", "scene_case"]


def scene_case(study, path):
    """The scene file ``path`` of the study as a case, ``system_overrides`` merged."""
    from ...case import load_case

    overrides = {f"system__{k}": v for k, v in study.spec.system_overrides.items()}
    return load_case(study.resolve(path), **overrides)


def prepare(study) -> None:
    """The load-time checks; builds ``study.spec`` (:class:`ClothStudySpec`)
    with the solver specs (the study's and each family's) validated once."""
    from ...case.specs import solver_spec
    from ...dynamics.work_precision import expand_methods

    d = study.data
    default = KINDS.get(study.kind, "kind").default_solver
    methods = _methods(d["methods"], default)
    try:
        expand_methods(methods)
    except InputError as exc:
        raise CaseFileError(f"methods: {exc}") from None
    ls = solver_spec(d["linear_solver"], "linear_solver", default_method=default)
    study.spec = spec = ClothStudySpec.from_data(d, ls, methods)
    for i, p in enumerate(spec.scenes):
        path = study.resolve(p)
        if not path.is_file():
            raise CaseFileError(f"scenes[{i}]: scene file not found: {path}")
        study.files.append(path)
        case = scene_case(study, p)
        if case.problem != "mass_spring" or case.spec.system["type"] != "cloth":
            raise CaseFileError(f"scenes[{i}]: {path.name} is not a cloth scene (system.type: cloth)")


def _methods(methods: list, default: str) -> list:
    """The method list with each family's own ``linear_solver`` mapping as a SolverSpec
    (validated like every solver spec: a typo names the key and the valid ones; ``default``: the
    method when a mapping names none, the kind's ``default_solver``)."""
    from ...case.specs import solver_spec

    return [{**m, "linear_solver": solver_spec(m["linear_solver"], f"methods[{i}].linear_solver",
                                               default_method=default)}
            if "linear_solver" in m else m for i, m in enumerate(methods)]


@dataclass(frozen=True)
class ClothReference:
    """``reference:`` of the cloth study (defaults: :func:`.schema.schema`)."""

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
                   system_overrides=plain(d.get("system_overrides") or {}),
                   frames=int(d["frames"]), dt=None if d.get("dt") is None else float(d["dt"]),
                   linear_solver=linear_solver, methods=plain(methods),
                   reference=ClothReference(float(ref["tol"]), str(ref["solve"]),
                                            str(ref["trajectory"]), int(ref["substeps"])))
