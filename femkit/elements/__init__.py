"""Finite elements below :mod:`femkit.fem`, :mod:`femkit.solids` and :mod:`femkit.dynamics`.

Two parts, neither importing any other femkit layer (only the shared leaves):

- the element abstraction: :class:`~femkit.elements.base.Element` objects, P1
  (:mod:`femkit.elements.p1`) and P2 (:mod:`femkit.elements.p2`) on triangles and tetrahedra,
  and the name registry :data:`ELEMENTS` (``get_element("P2", dim)``; an unknown name raises
  :class:`~femkit.errors.UnknownNameError` listing the valid ones). Importing them costs
  numpy only.
- :mod:`femkit.elements.compiled`: the compiled kernels of the elastic solids (deformation
  gradient, signed SVD, nodal-force scatter, element pass; numba, one file so that numba's
  per-file cache sees every edit). :mod:`femkit.solids` builds its bodies and generated energy
  modules on it, and projective dynamics' local step
  (:mod:`femkit.dynamics.integrators.projective_local`) uses the same kernels; neither of those
  packages imports the other. It is imported only by those who use it.

>>> get_element("P2", 3).n_dofs
10
>>> ELEMENTS.names()
['P1', 'P2']
"""

from __future__ import annotations

from ..registry import Registry
from .base import Element
from .p1 import ElementP1
from .p2 import ElementP2

__all__ = ["Element", "ElementP1", "ElementP2", "ELEMENTS", "get_element", "element_names"]

#: Element families by name; each entry builds the element for a dimension (2 or 3).
ELEMENTS: Registry[type] = Registry("element")
ELEMENTS.register("P1", ElementP1)
ELEMENTS.register("P2", ElementP2)

_MADE: dict[tuple[str, int], Element] = {}


def get_element(name: "str | Element", dim: int) -> Element:
    """The element registered as ``name`` on triangles (``dim=2``) or tetrahedra (``dim=3``).

    An :class:`Element` is returned as it is (its dimension checked). Raises
    :class:`~femkit.errors.UnknownNameError` naming the valid elements for an unknown name
    (``"P3"``, ``"p2x"``: names are case-sensitive, as in the case files).
    """
    if isinstance(name, Element):
        if name.dim != dim:
            from ..errors import InputError

            raise InputError(f"element {name.name} is for dimension {name.dim}, the mesh is {dim}D")
        return name
    key = (name, int(dim))
    if key not in _MADE:
        _MADE[key] = ELEMENTS.get(name)(int(dim))
    return _MADE[key]


def element_names() -> list[str]:
    """The registered element names (sorted), for schema enums and messages."""
    return ELEMENTS.names()
