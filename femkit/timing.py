"""Time in femkit: the one stage timer and the one way of printing a duration (standard library only).

:class:`StageTimer` accumulates wall-clock seconds per named stage (the case runners, the
studies and the distributed Poisson solve all time their stages with it);
:func:`format_seconds` writes a duration for people (plans, progress lines).

>>> timer = StageTimer()
>>> with timer("assembly"):
...     pass
>>> list(timer.times), timer.total >= 0.0
(['assembly'], True)
"""

from __future__ import annotations

import contextlib
import time

__all__ = ["StageTimer", "format_seconds"]


class StageTimer:
    """Accumulates wall-clock seconds per named stage (``time.perf_counter``)."""

    def __init__(self) -> None:
        self.times: dict[str, float] = {}

    @contextlib.contextmanager
    def __call__(self, stage: str):
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.times[stage] = self.times.get(stage, 0.0) + time.perf_counter() - t0

    @property
    def total(self) -> float:
        return float(sum(self.times.values()))


def format_seconds(s: float) -> str:
    """``0.42 -> '0.42 s'``, ``5400 -> '1.5 h'``, ``3e7 -> '347 d'``.

    >>> format_seconds(0.0042), format_seconds(90), format_seconds(5400), format_seconds(3e7)
    ('0.0042 s', '1.5 min', '1.5 h', '347 d')
    """
    s = float(s)
    if s < 60:
        return f"{s:.2g} s" if s < 10 else f"{s:.0f} s"
    if s < 3600:
        return f"{s / 60:.2g} min"
    if s < 86400 * 2:
        return f"{s / 3600:.2g} h"
    if s < 86400 * 365 * 2:
        return f"{s / 86400:.3g} d"
    return f"{s / (86400 * 365):.3g} years"
