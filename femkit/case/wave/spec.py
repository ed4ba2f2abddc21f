"""The typed run spec of a wave case: :class:`WaveSpec`, built once by
:func:`femkit.case.wave.run.prepare_wave` (``case.spec``)."""

from __future__ import annotations

from dataclasses import dataclass

from ..transient.setup import TransientSpec

__all__ = ["WaveSpec"]


@dataclass(frozen=True)
class WaveSpec(TransientSpec):
    """A :class:`~femkit.case.transient.setup.TransientSpec` whose ``capacity`` is ``rho`` (the
    initial velocity is the compiled expression ``case.functions["initial_velocity"]``)."""
