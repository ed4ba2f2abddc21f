"""Progress over a sweep's runs, and the point where a stop request ends the sweep.

The display is femkit's one progress helper (:mod:`femkit.progress`: a tqdm bar on a
terminal, one line per 10 % or per minute otherwise, nothing when disabled). Between runs a
stop request (SIGINT/SIGTERM under ``femkit study``: :func:`femkit.interrupt.active_flag`)
raises :class:`femkit.interrupt.Interrupted` naming the run that was about to start, so the
report directory is not replaced: the earlier report stays as it was.
"""

from __future__ import annotations

from typing import Iterable, Iterator, TypeVar

T = TypeVar("T")


def progress(items: Iterable[T], *, total: int | None = None, desc: str = "",
             enabled: bool | None = None) -> Iterator[T]:
    """Yield ``items`` with progress reported (``enabled=False``: silent); stop on request."""
    from ..interrupt import Interrupted, active_flag
    from ..progress import progress as report

    flag = active_flag()
    items = list(items)
    n = len(items) if total is None else total
    for i, item in enumerate(report(items, total=n, desc=desc, unit="run", enabled=enabled)):
        if flag:
            raise Interrupted(flag, where=f"before run {i + 1} of {n} ({i} done)")
        yield item
