"""Small input checks shared across femkit (standard library + numpy only).

>>> finite_nonnegative("2.5", "stiffness")
2.5
>>> finite_nonnegative(-1, "rtol")
Traceback (most recent call last):
...
femkit.errors.InputError: rtol must be finite and >= 0, got -1
"""

from __future__ import annotations

import math

from .errors import InputError


def finite_nonnegative(value, name: str) -> float:
    """``float(value)`` if it is a finite number ``>= 0``; :class:`InputError` naming ``name`` otherwise."""
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(f) or f < 0.0:
        raise InputError(f"{name} must be finite and >= 0, got {value!r}")
    return f


def mesh_size(h) -> float:
    """A target mesh size ``h``: a positive finite number (:class:`InputError` otherwise).

    >>> mesh_size("0.05")
    0.05
    """
    try:
        hv = float(h)
    except (TypeError, ValueError):
        raise InputError(f"mesh size h must be a positive number, got {h!r}") from None
    if not (math.isfinite(hv) and hv > 0):
        raise InputError(f"mesh size h must be a positive finite number, got {h!r}")
    return hv
