"""Freed memory handed back to the operating system: glibc's allocator (Linux), through ctypes.

NumPy allocates its arrays with ``malloc``. glibc serves a large request (at least
``M_MMAP_THRESHOLD``, 128 KiB at start) by its own ``mmap`` and unmaps it on ``free``; but each
such free raises the threshold to the freed size (up to 32 MiB on 64-bit), so after the first
large temporaries every array below that size comes from the heap, and the heap keeps what is
freed inside it: a run's resident memory then stays near the sum of everything it ever held
(the glibc manual, "Memory Allocation Tunables"; ``mallopt(3)``, ``malloc_trim(3)``).

:func:`tune_allocator` fixes the threshold (no dynamic raise), so large arrays are returned to
the system as soon as NumPy frees them (``femkit`` does it at start when ``FEMKIT_RETURN_MEMORY=1``,
:func:`from_environment`). It does nothing (and says so by returning False) where glibc is not
the allocator: another OS, musl, or a threshold the user set through ``MALLOC_MMAP_THRESHOLD_``,
which is left alone. (``malloc_trim(0)`` at every stage end was measured too: it returned nothing
measurable, so femkit does not call it.)

>>> ENVIRONMENT
'FEMKIT_RETURN_MEMORY'
"""

from __future__ import annotations

import os
import sys

__all__ = ["tune_allocator", "from_environment", "MMAP_THRESHOLD", "ENVIRONMENT"]

#: Set to 1 to have ``femkit`` return freed arrays to the system (:func:`tune_allocator`):
#: at 1.9M unknowns the fmg run's resident memory after the solve falls from ~0.93 to ~0.6 GB,
#: its peak (reached in the solve, live arrays) by 3 %, for about twice the page faults
#: (~1 s more CPU); so it is not the default.
ENVIRONMENT = "FEMKIT_RETURN_MEMORY"

#: ``M_MMAP_THRESHOLD`` set by :func:`tune_allocator`: requests from 1 MiB up get their own
#: mapping, given back when freed (each new one is faulted in afresh: the cost above); smaller
#: ones come from the heap.
MMAP_THRESHOLD = 1 << 20

_M_TRIM_THRESHOLD = -1  # mallopt parameter numbers, <malloc.h>
_M_MMAP_THRESHOLD = -3

_LIBC = None


def _glibc():
    """glibc's ``libc.so.6`` through ctypes, or None (not Linux, not glibc)."""
    global _LIBC
    if _LIBC is None:
        _LIBC = False
        if sys.platform.startswith("linux"):
            try:
                import ctypes

                libc = ctypes.CDLL("libc.so.6", use_errno=True)
                libc.gnu_get_libc_version  # glibc only (musl has no such symbol)
                libc.mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
                _LIBC = libc
            except (OSError, AttributeError):
                pass
    return _LIBC or None


def tune_allocator(mmap_threshold: int = MMAP_THRESHOLD) -> bool:
    """Fix glibc's mmap threshold at ``mmap_threshold`` bytes (and the heap's trim threshold at
    twice it), so arrays from that size up go back to the system when freed; True when set.

    Left alone when ``MALLOC_MMAP_THRESHOLD_`` is in the environment (the user's choice)."""
    libc = _glibc()
    if libc is None or "MALLOC_MMAP_THRESHOLD_" in os.environ:
        return False
    ok = libc.mallopt(_M_MMAP_THRESHOLD, int(mmap_threshold)) == 1
    return ok and libc.mallopt(_M_TRIM_THRESHOLD, 2 * int(mmap_threshold)) == 1


def from_environment() -> bool:
    """:func:`tune_allocator` when :data:`ENVIRONMENT` is ``1`` (the CLI calls this at start)."""
    if os.environ.get(ENVIRONMENT, "").strip().lower() in ("1", "true", "yes", "on"):
        return tune_allocator()
    return False

