"""The typed run spec of a scene: :class:`SceneSpec`, built once by the loader.

:func:`femkit.case.scene.run.prepare_scene` checks the validated file and builds this record;
the runner, the cost plan and the studies read it (``case.spec``) instead of the file's mapping.
Every default comes from the scene schema (:mod:`femkit.case.scene.schema`), filled before the
spec is built; the spec adds none of its own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

__all__ = ["SceneSpec", "OutputSpec", "StabilitySpec", "record_every"]


def record_every(steps: int, dt: float, out: Mapping[str, Any]) -> int:
    """Output cadence in steps: ``every``, else ``round(interval / dt)``, else enough steps for
    about ``frames`` frames (``ceil(steps / frames)``); the one place it is computed."""
    if "every" in out:
        return int(out["every"])
    if "interval" in out:
        return max(1, int(round(out["interval"] / dt)))
    return max(1, math.ceil(steps / int(out["frames"])))


@dataclass(frozen=True)
class OutputSpec:
    """``output:``: the directory (absolute), the cadence in steps and the files asked for."""

    dir: str
    every: int
    vtu: bool
    xdmf: bool
    energy_csv: bool
    png: bool
    gif: bool

    def files(self) -> tuple[str, ...]:
        """The outputs asked for, in the order of the cost model (``vtu``, ``xdmf`` ...)."""
        return tuple(k for k in ("vtu", "xdmf", "energy_csv", "png", "gif") if getattr(self, k))


@dataclass(frozen=True)
class StabilitySpec:
    """``stability:``: whether and how often the energy is checked, and its growth limit."""

    check: bool
    energy_growth_limit: float
    check_every: int


@dataclass(frozen=True)
class SceneSpec:
    """Everything a scene run needs, checked and resolved.

    Attributes
    ----------
    system : Mapping
        The ``system`` mapping (read-only; ``file`` absolute).
    forces : tuple of Mapping
        The declared forces, each ``{type: ..., params...}`` (the mapping form normalised).
    integrator : IntegratorSpec
    solver : SolverSpec
        The ``linear_solver`` (also ``case.solver``).
    dt, t_end : float
        Evaluated (constant expressions such as ``"1/60"`` allowed in the file).
    steps : int
        ``round(t_end / dt)``.
    output : OutputSpec
    stability : StabilitySpec
    contact : Mapping or None
        The ``contact:`` mapping (barrier contact, obstacle files absolute), None without one.
    """

    system: Mapping
    forces: tuple
    integrator: Any
    solver: Any
    dt: float
    t_end: float
    steps: int
    output: OutputSpec
    stability: StabilitySpec
    contact: Mapping | None = None
