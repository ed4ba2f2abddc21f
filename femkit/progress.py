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
(60 s) when that comes first, with the elapsed time and the predicted remaining time, so a log
shows that a long run is alive::

    scene hanging_cloth: 30% (60/200 steps), elapsed 12 s, remaining ~28 s

Lines are at least ``min_interval`` (5 s) apart, and the last one (100 %) is always printed: a
short run prints that one line only. The remaining time is the elapsed time scaled by the
predicted cost still to do over the predicted cost done (``cost=`` of :meth:`Progress.update`:
e.g. the triangles of a mesh level, the springs of a cloth, the steps of a run), so cheap first
runs do not promise a quick end; without costs every unit counts the same.

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
    every_fraction, every_seconds, min_interval : line cadence (lines mode)
    cost : predicted cost of all the work (same unit as the ``cost`` of :meth:`update`); the
        remaining time is then scaled by cost instead of by count
    """

    def __init__(self, total: int | None, desc: str = "", *, unit: str = "step", mode: str = "auto",
                 quiet: bool = False, stream=None, every_fraction: float = 0.1,
                 every_seconds: float = 60.0, min_interval: float = 5.0, cost: float | None = None,
                 clock=time.monotonic):
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
        self.min_interval = float(min_interval)
        self._last_line = self.start
        self.cost_total = float(cost) if cost else 0.0
        self.cost_done = 0.0
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
                if self.cost_total and self.cost_done > 0:
                    left = max(self.cost_total - self.cost_done, 0.0) / self.cost_done
                else:
                    left = (self.total - self.count) / self.count
                tail = f", remaining ~{format_seconds(elapsed * left)}"
            return f"{head}, elapsed {format_seconds(elapsed)}{tail}"
        return f"{self.desc}: {self.count} {self._units(self.count)}, elapsed {format_seconds(elapsed)}"

    def _emit(self, text: str) -> None:
        print(text, file=self.stream, flush=True)
        self.lines += 1

    def update(self, n: int = 1, cost: float | None = None) -> None:
        """Count ``n`` more units done, of predicted ``cost`` (see the class docstring; cheap:
        a comparison and a clock read, ~0.1 us)."""
        self.count += n
        if cost is not None:
            self.cost_done += float(cost)
        if self.mode == "off":
            return
        if self._bar is not None:
            self._bar.update(n)
            return
        due = bool(self.total) and self.count >= self._next_count
        now = None
        if due or (now := self.clock()) >= self._next_time:
            now = self.clock() if now is None else now
            last = bool(self.total) and self.count >= self.total
            if last or now >= self._next_time or now - self._last_line >= self.min_interval:
                self._emit(self.line())
                self._next_time = now + self.every_seconds
                self._last_line = now
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
        flag = getattr(exc, "flag", None)  # femkit.interrupt.Interrupted
        by = getattr(flag, "name", None) or ("SIGINT" if exc_type is KeyboardInterrupt else None)
        self.close(interrupted=by)


def progress(items: Iterable[T], *, total: int | None = None, desc: str = "", unit: str = "job",
             enabled: bool | None = None, mode: str = "auto", stream=None,
             stop=None, sizes=None, costs=None) -> Iterator[T]:
    """Iterate over ``items`` reporting progress (:class:`Progress`); ``enabled=False`` is quiet.

    ``stop``: a :class:`femkit.interrupt.StopFlag`; once set, the next item is not started:
    :class:`~femkit.interrupt.Interrupted` is raised naming it (``before run 3 of 8 (2 done)``).
    ``sizes``: how many units each item is (e.g. the runs of one mesh level: one per solver), so
    the count agrees with what the work reports; ``costs``: each item's predicted cost (the
    remaining time is scaled by it; see :class:`Progress`).

    >>> list(progress(range(3), enabled=False))
    [0, 1, 2]
    """
    items = list(items) if sizes is not None or costs is not None else items
    if sizes is not None:
        total = int(sum(sizes))
    elif total is None:
        try:
            total = len(items)  # type: ignore[arg-type]
        except TypeError:
            total = None
    bar = Progress(total, desc, unit=unit, mode=mode, quiet=enabled is False, stream=stream,
                   cost=sum(costs) if costs is not None else None)
    from .interrupt import active_flag

    done = 0
    try:
        for i, item in enumerate(items):
            if stop:
                from .interrupt import Interrupted

                of = f" of {total}" if total else ""
                raise Interrupted(stop, where=f"before {unit} {done + 1}{of} ({done} done)")
            yield item
            n = int(sizes[i]) if sizes is not None else 1
            done += n
            bar.update(n, cost=costs[i] if costs is not None else None)
    finally:
        flag = stop if stop is not None else active_flag()
        bar.close(interrupted=flag.name if flag else None)
