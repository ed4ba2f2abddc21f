"""Timers for study runs: per-stage wall times and minimum/median over repeats.

BLAS threads
------------
Small sparse solves get 10-20x slower when OpenBLAS spins up threads on a two-core machine,
so studies are timed with BLAS pinned to one thread. The variables must be set before numpy
is first imported; ``femkit study`` does so (:func:`pin_blas_threads` is called by the
command-line entry before anything imports numpy, and respects values the user already set).
From Python, set ``OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1`` in the environment yourself.

>>> t = StageTimer()
>>> with t("assembly"):
...     _ = sum(range(10))
>>> sorted(t.times) == ["assembly"] and t.times["assembly"] >= 0
True
"""

from __future__ import annotations

import os
import statistics
import time
from dataclasses import dataclass, field
from typing import Any, Callable

from ..timing import StageTimer  # noqa: F401  (re-exported: the studies time stages with it)

__all__ = ["BLAS_ENV", "pin_blas_threads", "StageTimer", "Timing", "time_call"]

#: Environment variables that pin BLAS / OpenMP thread pools.
BLAS_ENV = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def pin_blas_threads(threads: int = 1) -> dict:
    """Set the BLAS thread variables (only those not already set); returns the values in force.

    Effective only before numpy is imported for the first time.
    """
    for name in BLAS_ENV:
        os.environ.setdefault(name, str(threads))
    return {name: os.environ[name] for name in BLAS_ENV}


@dataclass
class Timing:
    """Repeated timings of one call: ``value`` is the last call's return value."""

    value: Any
    times: list = field(default_factory=list)

    @property
    def min(self) -> float:
        return float(min(self.times))

    @property
    def median(self) -> float:
        return float(statistics.median(self.times))


def time_call(fn: Callable[[], Any], *, repeats: int = 3, warmup: int = 1) -> Timing:
    """Call ``fn()`` ``warmup`` times untimed, then ``repeats`` times timed.

    The minimum is the usual figure of merit for run time (noise only ever adds time);
    the median is reported beside it.

    >>> t = time_call(lambda: 42, repeats=2, warmup=0)
    >>> t.value, len(t.times)
    (42, 2)
    """
    if repeats < 1:
        raise ValueError("repeats must be >= 1")
    for _ in range(max(0, warmup)):
        fn()
    times, value = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        value = fn()
        times.append(time.perf_counter() - t0)
    return Timing(value, times)
