"""Area and boundary length of each bundled geometry (what the triangle count is predicted from).

For a target size ``h`` gmsh's frontal-Delaunay mesher produces nearly equilateral triangles of
side ``h`` (area ``sqrt(3)/4 h^2``, i.e. ``2.31 / h^2`` triangles per unit area) plus a boundary
layer; :func:`femkit.cost.poisson.predict_triangles` uses ``c_A A / h^2 + c_L L / h`` with ``A``
the area and ``L`` the length of every mesh line (outer boundary, holes, and interfaces between
regions counted twice, since triangles on both sides follow them).

>>> area, length = domain_measures("unit_square")
>>> area, length
(1.0, 4.0)
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

from ..errors import InputError
from ..registry import Registry

__all__ = ["MEASURES", "domain_measures"]

#: ``name -> f(**params) -> (area, line_length)``, one entry per geometry of
#: :data:`femkit.mesh.GEOMETRIES` (same parameter names and defaults).
MEASURES: Registry[Callable[..., tuple[float, float]]] = Registry("geometry")


@MEASURES.register("rectangle")
def _rectangle(x0: float = 0.0, y0: float = 0.0, x1: float = 1.0, y1: float = 1.0):
    w, hgt = float(x1) - float(x0), float(y1) - float(y0)
    return w * hgt, 2.0 * (w + hgt)


@MEASURES.register("unit_square")
def _unit_square():
    return 1.0, 4.0


@MEASURES.register("l_shape")
def _l_shape():
    return 3.0, 8.0


@MEASURES.register("disk")
def _disk(centre: Sequence[float] = (0.0, 0.0), radius: float = 1.0):
    r = float(radius)
    return math.pi * r * r, 2.0 * math.pi * r


@MEASURES.register("annulus")
def _annulus(r_inner: float = 0.5, r_outer: float = 1.0, centre: Sequence[float] = (0.0, 0.0)):
    ri, ro = float(r_inner), float(r_outer)
    return math.pi * (ro * ro - ri * ri), 2.0 * math.pi * (ro + ri)


@MEASURES.register("checkerboard")
def _checkerboard(n: int = 4):
    n = int(n)
    return 1.0, 4.0 + 2.0 * 2.0 * (n - 1)  # 2 (n - 1) interior lines of length 1, counted twice


@MEASURES.register("square_with_inclusion")
def _square_with_inclusion(centre: Sequence[float] = (0.5, 0.5), radius: float = 0.25,
                           shape: str = "disk"):
    r = float(radius)
    inner = 2.0 * math.pi * r if shape == "disk" else 8.0 * r
    return 1.0, 4.0 + 2.0 * inner


def domain_measures(geometry: str, **params) -> tuple[float, float]:
    """``(area, line_length)`` of a named geometry with its parameters.

    Raises
    ------
    UnknownNameError
        Not a bundled geometry (the message lists them).
    InputError
        Unknown parameters, or parameters giving a non-positive area.
    """
    fn = MEASURES.get(geometry)
    try:
        area, length = fn(**params)
    except (TypeError, ValueError) as exc:
        raise InputError(f"geometry {geometry!r}: {exc}") from None
    if not (math.isfinite(area) and area > 0):
        raise InputError(f"geometry {geometry!r} with {params} has no positive area")
    return float(area), float(length)
