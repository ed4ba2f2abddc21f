"""The geometry registry: :class:`Geometry` records in :data:`GEOMETRIES`, added by
:func:`register_geometry` and built by :func:`generate` (see :mod:`femkit.mesh.geometries` for
what an entry holds and the tag conventions).
"""

from __future__ import annotations

import inspect
import math
from dataclasses import dataclass
from typing import Callable, Sequence

from ...errors import InputError
from ...registry import Registry
from ..mesh import Mesh

__all__ = ["GEOMETRIES", "Geometry", "register_geometry", "generate", "positive"]


@dataclass(frozen=True)
class Geometry:
    """One entry of :data:`GEOMETRIES` (see the module docstring).

    Attributes
    ----------
    name : the registered name
    build : ``build(h, **params) -> Mesh``
    measure : ``measure(**params) -> (measure, line_measure)``: area and mesh-line length (2D),
        or volume and mesh-surface area (3D); same parameters and defaults as ``build``
    dim : 2 or 3
    boundary_tags, cell_tags : the tag names of a generated mesh
    """

    name: str
    build: Callable[..., Mesh]
    measure: Callable[..., tuple[float, float]]
    dim: int = 2
    boundary_tags: tuple[str, ...] = ()
    cell_tags: tuple[str, ...] = ()

    @property
    def parameters(self) -> list[str]:
        """Names of the geometry's parameters (those of ``build`` after ``h``)."""
        return [n for n in inspect.signature(self.build).parameters if n != "h"]

    def check_params(self, h, params: dict) -> None:
        """Raise :class:`~femkit.errors.InputError` when ``params`` do not fit ``build``."""
        try:
            inspect.signature(self.build).bind(h, **params)
        except TypeError as exc:
            raise InputError(f"geometry {self.name!r}: {exc}; valid parameters: "
                             f"{', '.join(self.parameters) or '(none)'}") from None

    def measures(self, params: dict | None = None) -> tuple[float, float]:
        """``(measure, line_measure)`` of the geometry with ``params`` (floats, measure > 0).

        Raises
        ------
        InputError
            Unknown parameters, or parameters giving no positive measure.
        """
        params = dict(params or {})
        self.check_params(1.0, params)
        try:
            size, lines = self.measure(**params)
        except (TypeError, ValueError) as exc:
            raise InputError(f"geometry {self.name!r}: {exc}") from None
        size, lines = float(size), float(lines)
        if not (math.isfinite(size) and size > 0 and math.isfinite(lines) and lines >= 0):
            what = "area" if self.dim == 2 else "volume"
            raise InputError(f"geometry {self.name!r} with {params} has no positive {what}")
        return size, lines


#: ``name -> Geometry``: every geometry :func:`generate` (and a case file's ``mesh.geometry``)
#: knows.
GEOMETRIES: Registry[Geometry] = Registry("geometry")


def register_geometry(name: str, *, measure: Callable[..., tuple[float, float]], dim: int = 2,
                      boundary_tags: Sequence[str] = (), cell_tags: Sequence[str] = ()):
    """Decorator registering ``build`` as geometry ``name`` (see the module docstring).

    Returns ``build`` unchanged; a name registered twice raises ``ValueError``.
    """
    if dim not in (2, 3):
        raise ValueError(f"geometry {name!r}: dim must be 2 or 3, got {dim!r}")

    def decorator(build: Callable[..., Mesh]) -> Callable[..., Mesh]:
        GEOMETRIES.register(name, Geometry(name, build, measure, dim, tuple(boundary_tags),
                                           tuple(cell_tags)))
        return build

    return decorator


def generate(geometry: str, h: float, **params) -> Mesh:
    """Generate a mesh of a named geometry from :data:`GEOMETRIES`.

    Parameters
    ----------
    geometry : one of ``GEOMETRIES.names()`` (``annulus``, ``checkerboard``, ``disk``,
        ``l_shape``, ``rectangle``, ``square_with_inclusion``, ``unit_square``)
    h : target (maximal) element size
    **params : geometry parameters (e.g. ``r_inner`` for ``annulus``)

    Whether the mesh fits in memory is checked by the application before it calls this
    (``femkit.case.cost.check_mesh_fits``); the library itself does not plan.

    Raises
    ------
    UnknownNameError
        Unknown geometry (the message lists the valid ones).
    InputError
        Bad or unknown parameters.
    """
    entry = GEOMETRIES.get(geometry)
    entry.check_params(h, params)
    return entry.build(h, **params)



def positive(name: str, value) -> float:
    """A geometry parameter ``name`` that must be a positive finite number, as a float."""
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise InputError(f"{name} must be positive and finite, got {value!r}")
    return v
