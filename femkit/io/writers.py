"""The one JSON writer and the one CSV writer of femkit (both atomic, strict JSON).

>>> import tempfile, pathlib, numpy as np
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> _ = write_json(d / "r.json", {"x": np.float64(1.5), "bad": float("nan")})
>>> (d / "r.json").read_text()
'{\\n  "x": 1.5,\\n  "bad": null\\n}\\n'
>>> _ = write_csv(d / "t.csv", [{"a": 1, "b": 2.5}, {"a": 3, "c": [1, 2]}])
>>> print((d / "t.csv").read_text(), end="")
a,b,c
1,2.5,
3,,"[1, 2]"
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .atomic import atomic_write_text

__all__ = ["to_jsonable", "write_json", "write_csv"]


def to_jsonable(value: Any) -> Any:
    """Convert numpy scalars/arrays, paths and ``as_dict()`` objects to JSON types (strict JSON:
    non-finite floats become null; anything else unknown becomes its ``str``)."""
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else None
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if hasattr(value, "as_dict"):
        return to_jsonable(value.as_dict())
    if value is None or isinstance(value, (str, int)):
        return value
    return str(value)


def write_json(path: str | os.PathLike, data: Any) -> Path:
    """Write ``data`` as indented strict JSON (NaN/inf become null), atomically."""
    return atomic_write_text(path, json.dumps(to_jsonable(data), indent=2, allow_nan=False) + "\n")


def write_csv(path: str | os.PathLike, records: Sequence[dict], *, columns: Sequence[str] | None = None,
              float_format: str | None = None) -> Path:
    """One row per record, atomically; columns are ``columns`` or the union of keys in first-seen order.

    Missing values are empty cells; lists and mappings are written as JSON; ``float_format``
    (e.g. ``".17g"`` for round-trip exact numbers) formats floats.
    """
    cols: list[str] = list(columns or [])
    if columns is None:
        for r in records:
            for k in r:
                if k not in cols:
                    cols.append(k)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    for r in records:
        row = []
        for c in cols:
            v = to_jsonable(r.get(c))
            if v is None:
                row.append("")
            elif isinstance(v, (list, dict)):
                row.append(json.dumps(v))
            elif float_format and isinstance(v, float):
                row.append(format(v, float_format))
            else:
                row.append(v)
        w.writerow(row)
    return atomic_write_text(path, buf.getvalue())
