"""JSON-schema fragments shared by the file kinds' schemas (scenes, their forces and system types,
solids): positive numbers, vectors, node lists, closed objects."""

from __future__ import annotations

POS = {"type": "number", "exclusiveMinimum": 0}
NONNEG = {"type": "number", "minimum": 0}
COUNT2 = {"type": "integer", "minimum": 2}
VEC = {"type": "array", "minItems": 2, "maxItems": 3, "items": {"type": "number"}}
DIM = {"enum": [2, 3]}
NODES = {"type": "array", "items": {"type": "integer", "minimum": 0}}


def closed(props: dict, required: list[str]) -> dict:
    """An object schema admitting only ``props`` (a misspelt key names the valid ones)."""
    return {"type": "object", "additionalProperties": False, "required": list(required),
            "properties": props}


def pinned(named: list[str]) -> dict:
    """``pinned:``: one of the named node sets or a list of node indices."""
    return {"anyOf": [{"enum": named}, NODES],
            "x-message": f"expected one of {', '.join(named)} or a list of node indices"}
