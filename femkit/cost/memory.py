"""Memory of this machine and of this process (standard library only; Linux ``/proc`` first).

* :func:`available_memory` — bytes a new run may use: ``MemAvailable`` of ``/proc/meminfo``
  (the kernel's estimate of memory available without swapping), capped by a cgroup v2/v1
  limit when the process runs in a container; ``None`` when neither can be read.
* :func:`peak_rss` / :func:`reset_peak_rss` — the resident-set high-water mark
  (``VmHWM`` of ``/proc/self/status``), resettable since Linux 4.0 by writing ``5`` to
  ``/proc/self/clear_refs``; elsewhere ``ru_maxrss`` (not resettable). Used to measure the
  peak memory of a stage (calibration of the cost model, measured cost in results).

>>> rss = current_rss()
>>> rss is None or rss > 0
True
"""

from __future__ import annotations

import os
import sys

__all__ = ["available_memory", "current_rss", "peak_rss", "reset_peak_rss", "format_bytes"]

_CGROUP_LIMITS = ("/sys/fs/cgroup/memory.max",                     # cgroup v2
                  "/sys/fs/cgroup/memory/memory.limit_in_bytes")   # cgroup v1


def _proc_bytes(path: str, key: str) -> int | None:
    """The ``key:  <n> kB`` line of a ``/proc`` file, in bytes (``None`` when absent)."""
    try:
        with open(path) as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def _meminfo(key: str) -> int | None:
    return _proc_bytes("/proc/meminfo", key)


def _cgroup_room() -> int | None:
    """Bytes left under the cgroup memory limit (``None`` without a finite limit)."""
    for path in _CGROUP_LIMITS:
        try:
            text = open(path).read().strip()
        except OSError:
            continue
        if not text.isdigit():  # "max": no limit
            return None
        limit = int(text)
        if limit >= 1 << 60:    # v1 reports "no limit" as a huge number
            return None
        usage_file = os.path.join(os.path.dirname(path),
                                  "memory.current" if path.endswith("memory.max")
                                  else "memory.usage_in_bytes")
        try:
            usage = int(open(usage_file).read().strip())
        except (OSError, ValueError):
            usage = 0
        return max(limit - usage, 0)
    return None


def available_memory() -> int | None:
    """Bytes of memory a run can use now, or ``None`` when this platform does not say.

    ``MemAvailable`` (Linux >= 3.14), else ``MemFree + Cached``; the smaller of that and the
    room under a cgroup limit.
    """
    avail = _meminfo("MemAvailable")
    if avail is None:
        free, cached = _meminfo("MemFree"), _meminfo("Cached")
        avail = None if free is None else free + (cached or 0)
    room = _cgroup_room()
    if avail is None:
        return room
    return avail if room is None else min(avail, room)


def _status(key: str) -> int | None:
    return _proc_bytes("/proc/self/status", key)


def current_rss() -> int | None:
    """Resident set size of this process in bytes (``VmRSS``), ``None`` when unknown."""
    return _status("VmRSS")


def peak_rss() -> int | None:
    """High-water mark of the resident set in bytes (``VmHWM``, else ``ru_maxrss``)."""
    hwm = _status("VmHWM")
    if hwm is not None:
        return hwm
    try:
        import resource
    except ImportError:  # Windows
        return None
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return int(rss) if sys.platform == "darwin" else int(rss) * 1024


def reset_peak_rss() -> bool:
    """Reset the high-water mark to the current RSS; False when the platform cannot."""
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def format_bytes(n: float | None) -> str:
    """``1536 -> '1.5 KiB'``; binary units, three significant digits.

    >>> format_bytes(13 * 2**30), format_bytes(512), format_bytes(None)
    ('13 GiB', '512 B', 'unknown')
    """
    if n is None:
        return "unknown"
    n = float(n)
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024.0 or unit == "PiB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.3g} {unit}"
        n /= 1024.0
    return f"{n:.3g} PiB"  # pragma: no cover
