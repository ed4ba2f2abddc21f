"""Which preconditioner goes with which method: the one rule and its one message.

Only ``pcg`` takes a preconditioner. :func:`femkit.solvers.solve`, the solver spec of case,
scene and study files (:class:`femkit.solvers.SolverSpec`) and the PETSc backend's name table
all ask :func:`check_pairing`, so the rule is written once and reads the same everywhere.

>>> check_pairing("pcg", "ic0")
>>> check_pairing("cg", "ic0")
Traceback (most recent call last):
...
femkit.errors.InputError: preconditioner 'ic0' is only valid with method 'pcg', not 'cg' (use method 'pcg', or no preconditioner)
"""

from __future__ import annotations

from ...errors import InputError

__all__ = ["PRECONDITIONED_METHOD", "check_pairing"]

#: The one method that takes a preconditioner.
PRECONDITIONED_METHOD = "pcg"


def check_pairing(method: str, preconditioner: str | None) -> None:
    """Raise :class:`~femkit.errors.InputError` unless ``preconditioner`` (a name or a label of
    a preconditioner object; ``None``/``"none"``: no preconditioner) may go with ``method``."""
    if preconditioner in (None, "none") or method == PRECONDITIONED_METHOD:
        return
    raise InputError(f"preconditioner {preconditioner!r} is only valid with method "
                     f"{PRECONDITIONED_METHOD!r}, not {method!r} (use method "
                     f"{PRECONDITIONED_METHOD!r}, or no preconditioner)")
