"""Stage timers shared by the case runners and the studies (standard library only).

>>> timer = StageTimer()
>>> with timer("assembly"):
...     pass
>>> list(timer.times), timer.total >= 0.0
(['assembly'], True)
"""

from __future__ import annotations

import contextlib
import time


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
