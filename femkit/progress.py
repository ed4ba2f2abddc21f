"""Progress of long work: a tqdm bar on a terminal, plain log lines elsewhere, nothing when quiet.

One interface, :class:`Progress`, for every long piece of work, in three uses:

* counted work (time steps of a scene, runs of a study): ``Progress(total, desc)`` and
  ``update()``; :func:`progress` is the same object wrapped round an iterable, and with
  ``stop=`` (a :class:`femkit.interrupt.StopFlag`) it raises
  :class:`~femkit.interrupt.Interrupted` before the next item once a stop was requested;
* planned stages (a Poisson run whose stage times were predicted by a cost plan):
  :meth:`Progress.planned` and ``done(stage)``, see there.

On a terminal it shows a tqdm bar; when stderr is not a terminal (a log file, a batch
job, CI) it prints one line per ``every_fraction`` (10 %) of the work, or per ``every_seconds``
(60 s) when that comes first, with the elapsed time and the predicted remaining time (linear
extrapolation from the rate so far), so a log shows that a long run is alive::

    scene hanging_cloth: 30% (60/200 steps), elapsed 12 s, remaining ~28 s

>>> import io
>>> out = io.StringIO()
>>> with Progress(4, "demo", unit="job", mode="lines", stream=out) as bar:
...     for _ in range(4):
...         bar.update()
>>> out.getvalue().splitlines()[-1].split(",")[0]
'demo: 100% (4/4 jobs)'
"""

from __future__ import annotations

import sys
import time
from typing import Iterable, Iterator, TypeVar

from .timing import format_seconds

__all__ = ["Progress", "progress"]

T = TypeVar("T")

MODES = ("auto", "bar", "lines", "off")


def _isatty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


class Progress:
    """Counts work done out of ``total`` and reports it.

    Parameters
    ----------
    total : units of work (steps, jobs); ``None`` or 0 = unknown (lines then report counts only)
    desc : what runs (start of every line)
    unit : name of one unit (``"step"``, ``"job"``)
    mode : ``"auto"`` (bar on a terminal, lines otherwise), ``"bar"``, ``"lines"`` or ``"off"``
    quiet : same as ``mode="off"``
    stream : where to write (default ``sys.stderr``)
    every_fraction, every_seconds : line cadence (lines mode)
    """

    def __init__(self, total: int | None, desc: str = "", *, unit: str = "step", mode: str = "auto",
                 quiet: bool = False, stream=None, every_fraction: float = 0.1,
                 every_seconds: float = 60.0, clock=time.monotonic):
        if mode not in MODES:
            raise ValueError(f"progress mode must be one of {', '.join(MODES)}, got {mode!r}")
        self.stream = stream if stream is not None else sys.stderr
        if quiet:
            mode = "off"
        if mode == "auto":
            mode = "bar" if _isatty(self.stream) else "lines"
        self.mode = mode
        self.total = int(total) if total else 0
        self.desc, self.unit = desc, unit
        self.count = 0
        self.clock = clock
        self.start = clock()
        self.every_seconds = float(every_seconds)
        self._step = max(int(self.total * every_fraction), 1) if self.total else 0
        self._next_count = self._step if self.total else 0
        self._next_time = self.start + self.every_seconds
        self._bar = None
        self.lines = 0
        self.predicted: dict[str, float] = {}  # planned stages (see planned)
        self.done_predicted = 0.0
        if mode == "bar":
            from tqdm import tqdm

            self._bar = tqdm(total=self.total or None, desc=desc, unit=unit, leave=False,
                             file=self.stream)

    # ------------------------------------------------------------------ reporting
    def _units(self, n: int) -> str:
        return self.unit if n == 1 else self.unit + "s"

    def line(self) -> str:
        """The current status line (what lines mode prints)."""
        elapsed = self.clock() - self.start
        if self.total:
            frac = self.count / self.total
            head = f"{self.desc}: {100 * frac:.0f}% ({self.count}/{self.total} {self._units(self.total)})"
            tail = ""
            if 0 < self.count < self.total:
                tail = f", remaining ~{format_seconds(elapsed * (self.total - self.count) / self.count)}"
            return f"{head}, elapsed {format_seconds(elapsed)}{tail}"
        return f"{self.desc}: {self.count} {self._units(self.count)}, elapsed {format_seconds(elapsed)}"

    def _emit(self, text: str) -> None:
        print(text, file=self.stream, flush=True)
        self.lines += 1

    def update(self, n: int = 1) -> None:
        """Count ``n`` more units done (cheap: a comparison and a clock read, ~0.1 us)."""
        self.count += n
        if self.mode == "off":
            return
        if self._bar is not None:
            self._bar.update(n)
            return
        due = bool(self.total) and self.count >= self._next_count
        if due or self.clock() >= self._next_time:
            self._emit(self.line())
            self._next_time = self.clock() + self.every_seconds
            if self.total:
                while self._next_count <= self.count:
                    self._next_count += self._step

    @classmethod
    def planned(cls, stages, desc: str, *, quiet: bool = False, stream=None,
                min_seconds: float = 30.0, clock=time.monotonic) -> "Progress":
        """Progress of a run made of stages whose durations were predicted (a
        :class:`femkit.cost.Plan`'s ``(name, seconds)``).

        After each stage, :meth:`done` prints ``desc: assembly done, elapsed 12 s, remaining
        ~30 s`` (lines, also on a terminal), the remaining time being the predicted time of the
        stages left, scaled by how the elapsed time compares with its prediction. Only for runs
        predicted to take at least ``min_seconds`` (a short run stays silent), never when
        ``quiet``.

        >>> import io
        >>> out = io.StringIO()
        >>> clock = iter([0.0, 10.0, 30.0]).__next__
        >>> sp = Progress.planned([("mesh", 5.0), ("solve", 15.0)], "demo", stream=out,
        ...                       min_seconds=0, clock=clock)
        >>> sp.done("mesh"); sp.done("solve")
        >>> out.getvalue().splitlines()
        ['demo: mesh done, elapsed 10 s, remaining ~30 s', 'demo: solve done, elapsed 30 s']
        """
        predicted = {name: float(sec) for name, sec in stages}
        active = not quiet and sum(predicted.values()) >= min_seconds
        bar = cls(None, desc, unit="stage", mode="lines" if active else "off", stream=stream,
                  clock=clock)
        bar.predicted = predicted
        return bar

    def done(self, stage: str, *also: str) -> None:
        """Report that planned ``stage`` finished, with the planned stages ``also`` that the run
        did inside it (e.g. ``done("mesh", "refine")``) and every planned stage before them."""
        if self.mode == "off":
            return
        elapsed = self.clock() - self.start
        names = list(self.predicted)
        last = max((names.index(n) for n in (stage, *also) if n in self.predicted), default=-1)
        for name in names[: last + 1]:
            self.done_predicted += self.predicted.pop(name)
        left = sum(self.predicted.values())
        line = f"{self.desc}: {stage} done, elapsed {format_seconds(elapsed)}"
        if left > 0:
            pace = elapsed / self.done_predicted if self.done_predicted > 0 else 1.0
            line += f", remaining ~{format_seconds(left * pace)}"
        self._emit(line)

    def note(self, text: str) -> None:
        """Print a message between progress lines (through tqdm on a terminal)."""
        if self.mode == "off":
            return
        if self._bar is not None:
            self._bar.write(text, file=self.stream)
        else:
            self._emit(text)

    def close(self, interrupted: str | None = None) -> None:
        """Finish; with ``interrupted`` (e.g. ``"SIGTERM"``) say where the work stopped."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        if interrupted and self.mode != "off":
            self._emit(f"{self.line().split(', remaining')[0]}; interrupted by {interrupted}")

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close()


def progress(items: Iterable[T], *, total: int | None = None, desc: str = "", unit: str = "job",
             enabled: bool | None = None, mode: str = "auto", stream=None,
             stop=None) -> Iterator[T]:
    """Iterate over ``items`` reporting progress (:class:`Progress`); ``enabled=False`` is quiet.

    ``stop``: a :class:`femkit.interrupt.StopFlag`; once set, the next item is not started:
    :class:`~femkit.interrupt.Interrupted` is raised naming it (``before run 3 of 8 (2 done)``).

    >>> list(progress(range(3), enabled=False))
    [0, 1, 2]
    """
    if total is None:
        try:
            total = len(items)  # type: ignore[arg-type]
        except TypeError:
            total = None
    bar = Progress(total, desc, unit=unit, mode=mode, quiet=enabled is False, stream=stream)
    try:
        for i, item in enumerate(items):
            if stop:
                from .interrupt import Interrupted

                of = f" of {total}" if total else ""
                raise Interrupted(stop, where=f"before {unit} {i + 1}{of} ({i} done)")
            yield item
            bar.update()
    finally:
        bar.close()
