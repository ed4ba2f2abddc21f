"""The typed run spec of a solid case: :class:`SolidSpec`, built once by the loader
(:func:`femkit.case.solid.run.prepare_solid`); the runner, the plan and the outputs read it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping
from ...solvers.core import defaults

__all__ = ["SolidSpec", "Boundary", "StaticSpec", "SolidOutput"]


@dataclass(frozen=True)
class Boundary:
    """One boundary condition on the facets tagged ``tag``: ``kind`` ``fixed`` / ``roller``
    (``components`` prescribed to ``displacement``) or ``traction`` (force per rest area)."""

    tag: Any
    kind: str
    components: tuple = ()
    displacement: tuple = ()
    traction: tuple = ()


@dataclass(frozen=True)
class StaticSpec:
    """``static:`` settings of :func:`femkit.solids.solve_static`."""

    load_steps: int = 1
    project: Any = True
    max_iterations: int = 50
    rtol: float = field(default_factory=lambda: defaults.NEWTON_RTOL)


@dataclass(frozen=True)
class SolidOutput:
    """``output:``: directory (absolute), frame cadence in steps and the files asked for."""

    dir: str
    every: int
    vtu: bool
    png: bool
    gif: bool


@dataclass(frozen=True)
class SolidSpec:
    """Everything a solid run needs, checked and resolved at load time.

    Attributes
    ----------
    mesh : Mapping
        ``{geometry, h, params}`` or ``{file}`` (absolute).
    materials : Mapping
        region (tag name or number; ``None`` for every cell) -> Material.
    boundaries : tuple of Boundary
    gravity : tuple or None
    static : StaticSpec or None
        Set for a quasi-static run (then ``integrator`` is None).
    integrator : IntegratorSpec or None
    solver : SolverSpec
    dt, t_end : float or None (dynamic runs)
    steps : int
        Time steps (dynamic) or load steps (static).
    velocity : tuple or None
    output : SolidOutput
    element : str
        ``"P1"`` or ``"P2"`` (:data:`femkit.elements.ELEMENTS`).
    contact : Mapping or None
        The ``contact:`` mapping (barrier contact, :mod:`femkit.case.contact`), None without.
    bodies : tuple of Mapping or None
        ``bodies:``: per body its ``mesh`` (absolute file), ``material`` (a Material),
        ``offset`` and ``velocity`` (defaults: the file's ``mesh``, ``material``, ``velocity``).
    """

    mesh: Mapping
    materials: Mapping
    boundaries: tuple
    gravity: tuple | None
    static: StaticSpec | None
    integrator: Any
    solver: Any
    dt: float | None
    t_end: float | None
    steps: int
    velocity: tuple | None
    output: SolidOutput
    element: str = "P1"
    contact: Mapping | None = None
    bodies: tuple | None = None
