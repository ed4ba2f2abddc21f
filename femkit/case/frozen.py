"""Read-only views of validated file data: :func:`freeze`.

After loading, ``case.data`` and ``study.data`` are frozen: the runners read them, nothing edits
them in place (a run's settings are the typed spec built at load time). :class:`FrozenDict` and
:class:`FrozenList` are ``dict``/``list`` subclasses, so JSON writers, ``dict(...)`` and
``**`` unpacking work unchanged; ``copy.deepcopy`` returns plain mutable containers.

>>> d = freeze({"a": {"b": [1, 2]}})
>>> d["a"]["b"][0], dict(d["a"])
(1, {'b': [1, 2]})
>>> d["a"]["c"] = 3
Traceback (most recent call last):
...
TypeError: read-only data: loaded file data is not edited in place (copy it first)
"""

from __future__ import annotations

import copy
from typing import Any

__all__ = ["FrozenDict", "FrozenList", "freeze", "thaw"]


def _refuse(self, *args, **kwargs):
    raise TypeError("read-only data: loaded file data is not edited in place (copy it first)")


class FrozenDict(dict):
    """A ``dict`` that refuses every change."""

    __setitem__ = __delitem__ = clear = pop = popitem = setdefault = update = _refuse
    __ior__ = _refuse

    def __copy__(self) -> dict:
        return dict(self)

    def __deepcopy__(self, memo) -> dict:
        return {k: copy.deepcopy(v, memo) for k, v in self.items()}

    def __reduce__(self):
        return (dict, (thaw(self),))


class FrozenList(list):
    """A ``list`` that refuses every change."""

    __setitem__ = __delitem__ = append = extend = insert = pop = remove = clear = _refuse
    sort = reverse = __iadd__ = __imul__ = _refuse

    def __copy__(self) -> list:
        return list(self)

    def __deepcopy__(self, memo) -> list:
        return [copy.deepcopy(v, memo) for v in self]

    def __reduce__(self):
        return (list, (thaw(self),))


def freeze(obj: Any) -> Any:
    """``obj`` with every dict and list (recursively) made read-only."""
    if isinstance(obj, dict):
        return obj if isinstance(obj, FrozenDict) else FrozenDict(
            (k, freeze(v)) for k, v in obj.items())
    if isinstance(obj, list):
        return obj if isinstance(obj, FrozenList) else FrozenList(freeze(v) for v in obj)
    return obj


def thaw(obj: Any) -> Any:
    """A plain mutable deep copy of frozen (or any) data."""
    return copy.deepcopy(obj)
