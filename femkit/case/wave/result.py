"""The result of a wave run: :class:`WaveResult`, a :class:`~femkit.case.result.RunResult`
(through :class:`~femkit.case.transient.run.TransientResult`); ``result.json``'s keys are
described in docs/heat_wave.md."""

from __future__ import annotations

from dataclasses import dataclass

from ..transient.run import TransientResult

__all__ = ["WaveResult"]


@dataclass
class WaveResult(TransientResult):
    """Frames of ``u`` and ``v``, the error history against ``exact`` and the discrete energy
    ``1/2 v^T M v + 1/2 u^T K u`` per frame (``energy_drift``: its largest relative change)."""

    def kind_line(self) -> str:
        return f"wave      {self.case.name}"

    def facts(self) -> dict:
        out = super().facts()
        totals = [e["total"] for e in self.energies]
        ref = abs(totals[0]) if totals and totals[0] else None
        out["energy_drift"] = (max(abs(e - totals[0]) for e in totals) / ref) if ref else None
        return out
