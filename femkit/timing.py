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

__all__ = ["StageTimer", "WallClock", "process_age", "format_seconds"]

#: ``time.perf_counter()`` when femkit was first imported: the start-up estimate where the
#: operating system does not say when the process started.
_IMPORTED = time.perf_counter()


def process_age() -> float:
    """Seconds since this process started: from ``/proc`` on Linux (interpreter start-up and
    every import included), else since femkit was first imported."""
    try:
        import os

        with open("/proc/self/stat", "rb") as fh:
            stat = fh.read()
        with open("/proc/uptime", "rb") as fh:
            uptime = float(fh.read().split()[0])
        start_ticks = int(stat[stat.rindex(b")") + 2:].split()[19])  # field 22: starttime
        return max(uptime - start_ticks / os.sysconf("SC_CLK_TCK"), 0.0)
    except (OSError, ValueError, IndexError, AttributeError):
        return time.perf_counter() - _IMPORTED


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


class WallClock:
    """The whole process's wall time split into start-up, named stages and the rest.

    Created when a run starts: ``startup`` is the process's age then (interpreter, imports,
    reading the case). :meth:`facts` adds the stages of a :class:`StageTimer` and names what
    is left (``other``: bookkeeping between the stages), so the parts sum to ``total``.
    """

    def __init__(self) -> None:
        self.startup = process_age()
        self._t0 = time.perf_counter()

    def facts(self, stages: dict) -> dict:
        """``{"total", "startup", "stages", "other"}`` in seconds, up to now."""
        total = self.startup + time.perf_counter() - self._t0
        staged = float(sum(stages.values()))
        return {"total": total, "startup": self.startup, "stages": staged,
                "other": max(total - self.startup - staged, 0.0)}

    def summary(self, stages: dict) -> str:
        """One terminal line: ``wall 3.1 s = start-up and imports 0.9 s + stages 2.1 s + other 0.1 s``."""
        f = self.facts(stages)
        return (f"wall      {f['total']:.3f} s = start-up and imports {f['startup']:.3f} s + stages "
                f"{f['stages']:.3f} s + other {f['other']:.3f} s")


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
