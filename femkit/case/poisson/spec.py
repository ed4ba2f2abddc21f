"""The typed run spec of a Poisson case: :class:`PoissonSpec`, built once by the loader.

:func:`femkit.case.poisson.run.prepare_poisson` checks the validated file and builds this record
(``case.spec``); the pipeline's stages read it instead of the file's mapping. Every default comes
from the Poisson schema (:mod:`femkit.case.poisson.schema`, filled before the spec is built)
or, for the pure-Neumann settings, from :mod:`femkit.fem.poisson`; the spec adds none.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

__all__ = ["PoissonSpec", "MeshSpec", "BoundarySpec", "PoissonOutputSpec"]


@dataclass(frozen=True)
class MeshSpec:
    """``mesh:``: a named geometry at size ``h`` (with ``params``) or a ``file`` (absolute),
    refined uniformly ``refine`` times."""

    geometry: str | None
    h: float | None
    params: Mapping
    file: str | None
    refine: int

    @classmethod
    def from_mapping(cls, m: Mapping[str, Any]) -> "MeshSpec":
        return cls(m.get("geometry"), m.get("h"), m.get("params") or {}, m.get("file"),
                   int(m.get("refine") or 0))

    def source(self) -> str:
        """What ``result.json`` calls the mesh: the file, or ``geometry NAME h=H``."""
        return self.file if self.file is not None else f"geometry {self.geometry} h={self.h}"


@dataclass(frozen=True)
class BoundarySpec:
    """``boundary:``: Dirichlet and Neumann conditions (each ``{tags, value|flux}``); for a pure
    Neumann problem ``nullspace`` and ``compatibility_rtol`` (None otherwise)."""

    dirichlet: tuple
    neumann: tuple
    nullspace: str | None
    compatibility_rtol: float | None

    @property
    def pure_neumann(self) -> bool:
        return not self.dirichlet


@dataclass(frozen=True)
class PoissonOutputSpec:
    """``output:``: the directory (absolute) and the files asked for."""

    dir: str
    vtu: bool
    xdmf: bool
    plot: bool
    gather_limit: int | None
    compression: str = "none"


@dataclass(frozen=True)
class PoissonSpec:
    """Everything a Poisson run needs, checked and resolved.

    ``coefficient`` is a number, an expression (compiled in ``case.functions["coefficient"]``)
    or ``{regions: {...}, default: ...}``; ``solver`` is ``case.solver``; ``adaptive`` the
    ``adaptive:`` settings or None.
    """

    mesh: MeshSpec
    coefficient: Any
    boundary: BoundarySpec
    load_rule: str
    estimator: str
    adaptive: Mapping | None
    solver: Any
    output: PoissonOutputSpec
    element: str = "P1"
