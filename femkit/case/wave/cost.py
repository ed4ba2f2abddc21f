"""The plan of a wave case (``femkit solve --dry-run``, the time budget):
:func:`femkit.case.transient.setup.plan_transient`."""

from __future__ import annotations

__all__ = ["plan_wave_case"]


def plan_wave_case(case, *, measure: bool = True):
    """The :class:`femkit.cost.Plan` of a prepared wave case."""
    from ..transient.setup import plan_transient

    return plan_transient(case, measure=measure)
