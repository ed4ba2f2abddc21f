"""``python -m femkit.cli``: the ``femkit`` command (as ``python -m femkit``)."""

from __future__ import annotations

from . import entry

if __name__ == "__main__":  # pragma: no cover - the tests and benchmarks run it as a process
    entry()
