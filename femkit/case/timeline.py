"""The time grid of a time-dependent file (scenes, dynamic solids): ``dt`` and ``t_end``.

Every problem kind that integrates in time reads its step and end time here, so a scene and a
dynamic solid accept the same values: a positive number or a constant expression of the file's
``constants`` (``dt: "1/60"``).

>>> from types import SimpleNamespace
>>> time_value(SimpleNamespace(data={"dt": "1/4", "constants": {}}), "dt")
0.25
>>> time_value(SimpleNamespace(data={"dt": -1.0}), "dt")
Traceback (most recent call last):
...
femkit.errors.CaseFileError: dt: must be a positive finite number, got -1.0
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import CaseFileError, ExpressionError
from .expressions import compile_expression

__all__ = ["time_value"]


def time_value(case: Any, key: str) -> float:
    """``case.data[key]`` (``"dt"``, ``"t_end"``) as a positive finite number.

    Parameters
    ----------
    case : a case being prepared (its ``data`` validated by the kind's schema).
    key : the top-level key read.

    Raises
    ------
    ExpressionError
        A string that is not a constant expression (the key named in front).
    CaseFileError
        A value that is not positive and finite.
    """
    value = case.data[key]
    if isinstance(value, str):
        try:
            f = compile_expression(value, ("x",), case.data.get("constants") or {})
            value = float(f(np.zeros(1))[0])
        except ExpressionError as exc:
            raise ExpressionError(f"{key}: {exc}") from None
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise CaseFileError(f"{key}: must be a positive finite number, got {value!r}")
    return value
