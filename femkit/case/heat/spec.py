"""The typed run spec of a heat case: :class:`HeatSpec`, built once by
:func:`femkit.case.heat.run.prepare_heat` (``case.spec``)."""

from __future__ import annotations

from dataclasses import dataclass

from ..transient.setup import TransientSpec

__all__ = ["HeatSpec"]


@dataclass(frozen=True)
class HeatSpec(TransientSpec):
    """A :class:`~femkit.case.transient.setup.TransientSpec` whose ``capacity`` is ``rho_c`` and whose
    ``rtol_t``, when set, makes the steps adaptive (the integrator's embedded estimate: implicit
    Euler, Crank-Nicolson, BDF2)."""
