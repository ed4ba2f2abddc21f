"""The keys of a ``contact_penalty`` study file (JSON-schema properties)."""

from __future__ import annotations

__all__ = ["schema"]

_POS = {"type": "number", "exclusiveMinimum": 0}


def schema() -> dict:
    """The kind's own keys: the penalty stiffnesses swept and the dropped cloth."""
    return {
        "stiffnesses": {"type": "array", "minItems": 1, "items": _POS,
                        "default": [1.0e2, 1.0e3, 1.0e4, 1.0e5],
                        "description": "penalty ground stiffnesses k_c"},
        "n": {"type": "integer", "minimum": 2, "default": 8,
              "description": "cloth vertices per side"},
        "height": {**_POS, "default": 0.05, "description": "drop height of the cloth"},
        "dt": {**_POS, "default": 0.005},
        "t_end": {**_POS, "default": 0.3},
    }
