"""The result of a heat run: :class:`HeatResult`, a :class:`~femkit.case.result.RunResult`
(through :class:`~femkit.case.transient.run.TransientResult`); ``result.json``'s keys are
described in docs/heat_wave.md."""

from __future__ import annotations

from dataclasses import dataclass

from ..transient.run import TransientResult

__all__ = ["HeatResult"]


@dataclass
class HeatResult(TransientResult):
    """Frames of ``u``, the error history against ``exact``, the thermal energy
    ``1/2 u^T M u`` and the Dirichlet energy ``1/2 u^T K u`` per frame."""

    def kind_line(self) -> str:
        return f"heat      {self.case.name}"
