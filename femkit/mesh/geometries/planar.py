"""The 2D geometries (triangles, meshed by gmsh): rectangle, unit_square, l_shape, disk,
annulus, checkerboard, square_with_inclusion; each registered in
:data:`~femkit.mesh.geometries.GEOMETRIES` with its measure and tags.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ...errors import InputError
from ...validation import mesh_size as _check_h
from ..mesh import Mesh
from .gmsh_session import gmsh_session, mesh_from_gmsh, physical_group, run_mesher, set_size
from .registry import positive, register_geometry

__all__ = ["rectangle", "unit_square", "l_shape", "disk", "annulus", "checkerboard",
           "square_with_inclusion"]


def _side_groups(gmsh, left: list[int], right: list[int], bottom: list[int], top: list[int]) -> None:
    """Edge groups 1..5 of a rectangle: left, right, bottom, top and boundary (all four)."""
    for k, (name, lines) in enumerate((("left", left), ("right", right),
                                       ("bottom", bottom), ("top", top)), start=1):
        physical_group(gmsh, 1, lines, name, k)
    physical_group(gmsh, 1, left + right + bottom + top, "boundary", 5)


def _finish(gmsh, h: float) -> Mesh:
    gmsh.model.geo.synchronize()
    set_size(gmsh, h)
    run_mesher(gmsh, 2)
    return mesh_from_gmsh(gmsh)


def _polygon(geo, xy: Sequence[tuple[float, float]], h: float) -> list[int]:
    """Closed polygon through ``xy`` (CCW); returns the line tags, line i from xy[i] to xy[i+1]."""
    pts = [geo.addPoint(x, y, 0.0, h) for x, y in xy]
    return [geo.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]


def _circle(geo, cx: float, cy: float, r: float, h: float) -> list[int]:
    """Circle as four arcs (CCW); returns the arc tags."""
    c = geo.addPoint(cx, cy, 0.0, h)
    p = [geo.addPoint(cx + r * math.cos(a), cy + r * math.sin(a), 0.0, h)
         for a in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi)]
    return [geo.addCircleArc(p[i], c, p[(i + 1) % 4]) for i in range(4)]


def _rectangle_measure(x0: float = 0.0, y0: float = 0.0, x1: float = 1.0, y1: float = 1.0):
    w, hgt = float(x1) - float(x0), float(y1) - float(y0)
    return w * hgt, 2.0 * (w + hgt)


_SIDES = ("left", "right", "bottom", "top", "boundary")


@register_geometry("rectangle", measure=_rectangle_measure, boundary_tags=_SIDES,
                   cell_tags=("domain",))
def rectangle(h: float, x0: float = 0.0, y0: float = 0.0, x1: float = 1.0, y1: float = 1.0) -> Mesh:
    """Rectangle ``[x0, x1] x [y0, y1]``.

    Edge tags: ``left`` (x = x0), ``right`` (x = x1), ``bottom`` (y = y0), ``top`` (y = y1),
    ``boundary`` (all four). Cell tag: ``domain``.
    """
    h = _check_h(h)
    x0, y0, x1, y1 = map(float, (x0, y0, x1, y1))
    if not (x1 > x0 and y1 > y0):
        raise InputError(f"rectangle needs x1 > x0 and y1 > y0, got ({x0}, {y0}, {x1}, {y1})")
    with gmsh_session("rectangle") as gmsh:
        geo = gmsh.model.geo
        bottom, right, top, left = _polygon(geo, [(x0, y0), (x1, y0), (x1, y1), (x0, y1)], h)
        surf = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, top, left])])
        geo.synchronize()
        _side_groups(gmsh, [left], [right], [bottom], [top])
        physical_group(gmsh, 2, [surf], "domain", 6)
        return _finish(gmsh, h)


@register_geometry("unit_square", measure=lambda: (1.0, 4.0), boundary_tags=_SIDES,
                   cell_tags=("domain",))
def unit_square(h: float) -> Mesh:
    """Unit square ``[0, 1]^2``, the origin at its lower-left corner.

    Edge tags: ``left`` (x = 0), ``right`` (x = 1), ``bottom`` (y = 0), ``top`` (y = 1),
    ``boundary`` (all four). Cell tag: ``domain``.
    """
    return rectangle(h, 0.0, 0.0, 1.0, 1.0)


@register_geometry("l_shape", measure=lambda: (3.0, 8.0),
                   boundary_tags=("reentrant", "outer", "boundary"), cell_tags=("domain",))
def l_shape(h: float) -> Mesh:
    """L-shaped domain ``(-1, 1)^2`` minus the quadrant ``[0, 1] x [-1, 0]``.

    The re-entrant corner is the origin (interior angle 3 pi / 2); with ``theta`` in
    ``[0, 2 pi)`` the singular solution ``r^(2/3) sin(2 theta / 3)`` vanishes on both edges
    meeting there. Edge tags: ``reentrant`` (the two edges meeting at the origin: x = 0,
    -1 <= y <= 0 and y = 0, 0 <= x <= 1), ``outer`` (the other four edges), ``boundary`` (all).
    Cell tag: ``domain``.
    """
    h = _check_h(h)
    with gmsh_session("l_shape") as gmsh:
        geo = gmsh.model.geo
        lines = _polygon(geo, [(-1, -1), (0, -1), (0, 0), (1, 0), (1, 1), (-1, 1)], h)
        surf = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        geo.synchronize()
        reentrant = [lines[1], lines[2]]  # (0,-1)->(0,0) and (0,0)->(1,0)
        outer = [lines[0], lines[3], lines[4], lines[5]]
        physical_group(gmsh, 1, reentrant, "reentrant", 1)
        physical_group(gmsh, 1, outer, "outer", 2)
        physical_group(gmsh, 1, lines, "boundary", 3)
        physical_group(gmsh, 2, [surf], "domain", 4)
        return _finish(gmsh, h)


def _disk_measure(centre: Sequence[float] = (0.0, 0.0), radius: float = 1.0):
    r = float(radius)
    return math.pi * r * r, 2.0 * math.pi * r


@register_geometry("disk", measure=_disk_measure, boundary_tags=("outer", "boundary"),
                   cell_tags=("domain",))
def disk(h: float, centre: Sequence[float] = (0.0, 0.0), radius: float = 1.0) -> Mesh:
    """Disk of ``radius`` about ``centre``.

    Edge tags: ``outer`` (the circle) and ``boundary`` (the same edges). Cell tag: ``domain``.
    """
    h = _check_h(h)
    r = positive("radius", radius)
    cx, cy = map(float, centre)
    with gmsh_session("disk") as gmsh:
        geo = gmsh.model.geo
        arcs = _circle(geo, cx, cy, r, h)
        surf = geo.addPlaneSurface([geo.addCurveLoop(arcs)])
        geo.synchronize()
        physical_group(gmsh, 1, arcs, "outer", 1)
        physical_group(gmsh, 1, arcs, "boundary", 2)
        physical_group(gmsh, 2, [surf], "domain", 3)
        return _finish(gmsh, h)


def _annulus_measure(r_inner: float = 0.5, r_outer: float = 1.0,
                     centre: Sequence[float] = (0.0, 0.0)):
    ri, ro = float(r_inner), float(r_outer)
    return math.pi * (ro * ro - ri * ri), 2.0 * math.pi * (ro + ri)


@register_geometry("annulus", measure=_annulus_measure,
                   boundary_tags=("inner", "outer", "boundary"), cell_tags=("domain",))
def annulus(h: float, r_inner: float = 0.5, r_outer: float = 1.0,
            centre: Sequence[float] = (0.0, 0.0)) -> Mesh:
    """Annulus ``r_inner < |x - centre| < r_outer``.

    Edge tags: ``inner``, ``outer``, ``boundary`` (both circles). Cell tag: ``domain``.
    """
    h = _check_h(h)
    ri, ro = positive("r_inner", r_inner), positive("r_outer", r_outer)
    if not ri < ro:
        raise InputError(f"annulus needs r_inner < r_outer, got {ri} and {ro}")
    cx, cy = map(float, centre)
    with gmsh_session("annulus") as gmsh:
        geo = gmsh.model.geo
        outer = _circle(geo, cx, cy, ro, h)
        inner = _circle(geo, cx, cy, ri, h)
        surf = geo.addPlaneSurface([geo.addCurveLoop(outer), geo.addCurveLoop(inner)])
        geo.synchronize()
        physical_group(gmsh, 1, inner, "inner", 1)
        physical_group(gmsh, 1, outer, "outer", 2)
        physical_group(gmsh, 1, outer + inner, "boundary", 3)
        physical_group(gmsh, 2, [surf], "domain", 4)
        return _finish(gmsh, h)


def _checkerboard_measure(n: int = 4):
    # 2 (n - 1) interior lines of length 1, counted twice
    return 1.0, 4.0 + 2.0 * 2.0 * (int(n) - 1)


@register_geometry("checkerboard", measure=_checkerboard_measure, boundary_tags=_SIDES,
                   cell_tags=("high", "low"))
def checkerboard(h: float, n: int = 4) -> Mesh:
    """Unit square ``[0, 1]^2`` split into ``n x n`` equal squares tagged alternately ``high`` and
    ``low``.

    Square ``(i, j)`` (column i, row j, from the origin) is ``high`` when ``i + j`` is even.
    Every square boundary is a mesh line, so a per-region coefficient jumps exactly across
    element edges. Edge tags: ``left``, ``right``, ``bottom``, ``top``, ``boundary``.
    Cell tags: ``high``, ``low`` (no ``domain`` group).
    """
    h = _check_h(h)
    if int(n) != n or n < 1:
        raise InputError(f"checkerboard needs a positive integer n, got {n!r}")
    n = int(n)
    if n == 1:
        raise InputError("checkerboard needs n >= 2 (n = 1 is unit_square)")
    with gmsh_session("checkerboard") as gmsh:
        geo = gmsh.model.geo
        t = np.linspace(0.0, 1.0, n + 1)
        p = [[geo.addPoint(float(t[i]), float(t[j]), 0.0, h) for j in range(n + 1)]
             for i in range(n + 1)]
        hor = [[geo.addLine(p[i][j], p[i + 1][j]) for j in range(n + 1)] for i in range(n)]
        ver = [[geo.addLine(p[i][j], p[i][j + 1]) for j in range(n)] for i in range(n + 1)]
        high, low = [], []
        for i in range(n):
            for j in range(n):
                loop = geo.addCurveLoop([hor[i][j], ver[i + 1][j], -hor[i][j + 1], -ver[i][j]])
                (high if (i + j) % 2 == 0 else low).append(geo.addPlaneSurface([loop]))
        geo.synchronize()
        left = [ver[0][j] for j in range(n)]
        right = [ver[n][j] for j in range(n)]
        bottom = [hor[i][0] for i in range(n)]
        top = [hor[i][n] for i in range(n)]
        _side_groups(gmsh, left, right, bottom, top)
        physical_group(gmsh, 2, high, "high", 6)
        physical_group(gmsh, 2, low, "low", 7)
        return _finish(gmsh, h)


def _inclusion_measure(centre: Sequence[float] = (0.5, 0.5), radius: float = 0.25,
                       shape: str = "disk"):
    r = float(radius)
    inner = 2.0 * math.pi * r if shape == "disk" else 8.0 * r
    return 1.0, 4.0 + 2.0 * inner


@register_geometry("square_with_inclusion", measure=_inclusion_measure, boundary_tags=_SIDES,
                   cell_tags=("matrix", "inclusion"))
def square_with_inclusion(h: float, centre: Sequence[float] = (0.5, 0.5), radius: float = 0.25,
                          shape: str = "disk") -> Mesh:
    """Unit square ``[0, 1]^2`` with an inclusion about ``centre``: ``shape`` ``disk`` (of
    ``radius``) or ``square`` (of half-side ``radius``).

    The inclusion boundary is a mesh line (the two regions are conforming). Edge tags: ``left``,
    ``right``, ``bottom``, ``top``, ``boundary`` (outer square only). Cell tags: ``matrix``
    (outside) and ``inclusion`` (inside; no ``domain`` group).
    """
    h = _check_h(h)
    r = positive("radius", radius)
    cx, cy = map(float, centre)
    if shape not in ("disk", "square"):
        raise InputError(f"inclusion shape must be 'disk' or 'square', got {shape!r}")
    if not (cx - r > 0 and cx + r < 1 and cy - r > 0 and cy + r < 1):
        raise InputError(f"inclusion (centre {centre}, radius {r}) must lie strictly inside the unit square")
    with gmsh_session("square_with_inclusion") as gmsh:
        geo = gmsh.model.geo
        bottom, right, top, left = _polygon(geo, [(0, 0), (1, 0), (1, 1), (0, 1)], h)
        if shape == "disk":
            inner = _circle(geo, cx, cy, r, h)
        else:
            inner = _polygon(geo, [(cx - r, cy - r), (cx + r, cy - r), (cx + r, cy + r),
                                   (cx - r, cy + r)], h)
        inner_loop = geo.addCurveLoop(inner)
        matrix = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, top, left]), inner_loop])
        inclusion = geo.addPlaneSurface([inner_loop])
        geo.synchronize()
        _side_groups(gmsh, [left], [right], [bottom], [top])
        physical_group(gmsh, 2, [matrix], "matrix", 6)
        physical_group(gmsh, 2, [inclusion], "inclusion", 7)
        return _finish(gmsh, h)
