"""``python -m femkit``: the same command line as the ``femkit`` script.

Useful where the console script is not on ``PATH`` (a virtual environment not activated, a
Windows user install): ``python -m femkit solve cases/poisson_unit_square.yaml``.
"""

from __future__ import annotations

from .cli import entry

if __name__ == "__main__":  # pragma: no cover - exercised by tests/cli/test_newcomer_edges.py
    entry()
