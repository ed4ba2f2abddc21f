"""Explicit name -> factory registries (solvers, preconditioners, integrators, geometries).

An unknown name raises :class:`~femkit.errors.UnknownNameError` listing the valid
names; there is never a silent fallback to another method.

>>> reg = Registry("colour")
>>> @reg.register("red")
... def make_red():
...     return "#f00"
>>> reg.get("red")()
'#f00'
>>> reg.get("blue")
Traceback (most recent call last):
...
femkit.errors.UnknownNameError: unknown colour 'blue'; valid colours: red
"""

from __future__ import annotations

from typing import Generic, Iterator, TypeVar

from .errors import UnknownNameError

T = TypeVar("T")


class Registry(Generic[T]):
    """A name -> object mapping that refuses unknown names loudly."""

    def __init__(self, kind: str):
        self.kind = kind
        self._items: dict[str, T] = {}

    def register(self, name: str, obj: T | None = None):
        """Register ``obj`` under ``name``; usable as a decorator when ``obj`` is omitted."""
        if obj is not None:
            self._add(name, obj)
            return obj

        def decorator(o: T) -> T:
            self._add(name, o)
            return o

        return decorator

    def _add(self, name: str, obj: T) -> None:
        if name in self._items:
            raise ValueError(f"{self.kind} {name!r} registered twice")
        self._items[name] = obj

    def get(self, name: str) -> T:
        """Return the object registered as ``name`` or raise :class:`UnknownNameError`."""
        try:
            return self._items[name]
        except (KeyError, TypeError):
            raise UnknownNameError(self.kind, str(name), self._items) from None

    def remove(self, name: str) -> T:
        """Unregister ``name`` and return its object (UnknownNameError if absent)."""
        obj = self.get(name)
        del self._items[name]
        return obj

    def names(self) -> list[str]:
        return sorted(self._items)

    def __contains__(self, name: object) -> bool:
        return name in self._items

    def __iter__(self) -> Iterator[str]:
        return iter(self.names())

    def __len__(self) -> int:
        return len(self._items)
