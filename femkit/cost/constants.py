"""The cost model's constants: shipped calibration, overridable per machine.

The shipped values (``femkit/cost/constants.json``) were fitted by
``benchmarks/calibrate_cost.py`` on the machine described in ``docs/benchmarks.md``. A machine
that is faster or slower, or has other library versions, overrides any of them, in this order
(later wins):

1. the shipped ``constants.json``;
2. ``$XDG_CONFIG_HOME/femkit/cost.json`` (default ``~/.config/femkit/cost.json``);
3. the file named by the environment variable ``FEMKIT_COST_CONSTANTS``.

An override file holds the same nested keys (only those it changes), e.g.
``{"seconds": {"gmsh_per_triangle": 4e-5}}``; ``python benchmarks/calibrate_cost.py --write
~/.config/femkit/cost.json`` measures and writes a complete one. Keys starting with ``_`` are
comments. An unknown key is an error (a typo would otherwise be ignored silently).

>>> c = load_constants()
>>> 2.0 < c["mesh"]["triangles_per_area_h2"] < 2.6
True
"""

from __future__ import annotations

import copy
import json
import os
from pathlib import Path

from ..errors import InputError

__all__ = ["load_constants", "constants_sources", "ENV_VAR"]

ENV_VAR = "FEMKIT_COST_CONSTANTS"
_SHIPPED = Path(__file__).with_name("constants.json")
_CACHE: dict = {}


def _user_file() -> Path:
    base = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"), ".config")
    return Path(base) / "femkit" / "cost.json"


def constants_sources() -> list[Path]:
    """Files that make up the constants, shipped first (only those that exist)."""
    out = [_SHIPPED]
    if _user_file().is_file():
        out.append(_user_file())
    env = os.environ.get(ENV_VAR)
    if env:
        if not os.path.isfile(env):
            raise InputError(f"{ENV_VAR}={env}: no such file (a JSON file of cost-model constants)")
        out.append(Path(env))
    return out


def _merge(base: dict, over: dict, where: str, path: str = "") -> None:
    for key, value in over.items():
        if key.startswith("_"):
            continue
        if key not in base:
            valid = ", ".join(k for k in sorted(base) if not k.startswith("_"))
            raise InputError(f"{where}: unknown cost constant {path}{key}; valid keys here: {valid}")
        if isinstance(base[key], dict):
            if not isinstance(value, dict):
                raise InputError(f"{where}: cost constant {path}{key} must be a mapping")
            _merge(base[key], value, where, f"{path}{key}.")
        else:
            if not isinstance(value, (int, float)) or isinstance(value, bool) or value < 0:
                raise InputError(f"{where}: cost constant {path}{key} must be a non-negative "
                                 f"number, got {value!r}")
            base[key] = float(value)


def load_constants(extra: dict | None = None) -> dict:
    """The merged constants (a fresh copy), with ``extra`` (same nested form) applied last.

    Raises
    ------
    InputError
        An override file that is not JSON, has unknown keys or non-numeric values.
    """
    sources = constants_sources()
    key = tuple((str(p), p.stat().st_mtime) for p in sources)
    if key not in _CACHE:
        merged = json.loads(_SHIPPED.read_text())
        for p in sources[1:]:
            try:
                over = json.loads(p.read_text())
            except (OSError, ValueError) as exc:
                raise InputError(f"{p}: not a readable JSON file of cost constants ({exc})") from None
            if not isinstance(over, dict):
                raise InputError(f"{p}: cost constants must be a JSON object")
            _merge(merged, over, str(p))
        _CACHE.clear()
        _CACHE[key] = merged
    out = copy.deepcopy(_CACHE[key])
    if extra:
        _merge(out, extra, "constants")
    return out
