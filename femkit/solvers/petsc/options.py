"""``petsc_options``: any PETSc option passed through, as on PETSc's command line.

``{"ksp_monitor_true_residual": None, "pc_hypre_boomeramg_strong_threshold": 0.5}`` acts like
``-ksp_monitor_true_residual -pc_hypre_boomeramg_strong_threshold 0.5``. Keys may carry the
leading ``-`` or not; values are numbers, strings, booleans or ``None`` (a flag). The options
go into PETSc's options database under a prefix private to one solve (so two solves never
see each other's options) and are removed afterwards. An option PETSc rejects (a bad type
name or value) and an option nothing used (a misspelt key) raise
:class:`~femkit.errors.InputError` with one line.
"""

from __future__ import annotations

import itertools
from contextlib import contextmanager

from ...errors import InputError

_counter = itertools.count()


def option_text(value) -> str:
    """An option value as PETSc's options database stores it."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float, str)):
        return str(value)
    raise InputError(f"petsc_options values must be numbers, strings, booleans or null, "
                     f"got {type(value).__name__}")


def normalise(options: dict | None) -> dict[str, str]:
    """``{name without '-': text}``; bad keys or values raise :class:`InputError`."""
    out = {}
    for key, value in (options or {}).items():
        if not isinstance(key, str) or not key.lstrip("-") or " " in key:
            raise InputError(f"petsc_options keys must be option names such as 'ksp_rtol', "
                             f"got {key!r}")
        out[key.lstrip("-")] = option_text(value)
    return out


def new_prefix() -> str:
    """A fresh options prefix (``femkit3_``), the same on every rank when solves are collective."""
    return f"femkit{next(_counter)}_"


@contextmanager
def scoped(prefix: str, options: dict[str, str]):
    """Insert ``options`` under ``prefix`` into PETSc's database for the ``with`` block."""
    from .env import require_petsc

    opts = require_petsc().Options()
    for key, value in options.items():
        opts.setValue(prefix + key, value)
    try:
        yield
    finally:
        for key in options:
            opts.delValue(prefix + key)


def check_used(prefix: str, user: dict[str, str]) -> None:
    """Raise :class:`InputError` naming the user options that nothing read (misspelt or not
    applicable to the chosen KSP/PC)."""
    from .clib import option_used

    unused = [k for k in user if not option_used(prefix + k)]
    if unused:
        raise InputError(f"PETSc did not use petsc_options {', '.join(unused)} (misspelt, or not "
                         f"applicable to the chosen KSP/PC)")


def petsc_error_text(exc) -> str:
    """One line from a ``PETSc.Error`` (its code and PETSc's own first message line if any)."""
    text = str(exc).strip().splitlines()
    return text[0] if text else f"PETSc error {getattr(exc, 'ierr', '?')}"
