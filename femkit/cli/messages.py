"""How the ``femkit`` command answers: its exit codes, errors and warnings on one line, and
under ``mpirun`` only rank 0 speaking.
"""

from __future__ import annotations

import sys

#: success; ran but failed its goal; bad input (or a cost above a budget)
EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2


def one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """How the command line shows a Python warning: ``femkit: warning: <message>`` on one line
    (no file name, line number or source line: the user did not write that code)."""
    text = one_line(message)
    if not issubclass(category, UserWarning):
        text = f"{text} ({category.__name__})"  # e.g. numpy's RuntimeWarning: say what it is
    print(f"femkit: warning: {text}", file=file or sys.stderr)


def mpi_rank() -> int:
    """This process's MPI rank from the launcher's environment (0 outside mpirun)."""
    import os

    for var in ("OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"):
        if os.environ.get(var, "").isdigit():
            return int(os.environ[var])
    return 0


def one_line(exc: BaseException) -> str:
    """The message of ``exc`` with its white space (newlines too) collapsed to single spaces."""
    return " ".join(str(exc).split())

