"""Cook's membrane: the tapered panel of the classic bending-with-shear benchmark.

The panel has the corners ``(0, 0)``, ``(48, 44)``, ``(48, 60)``, ``(0, 44)``: clamped on its
left edge ``x = 0``, loaded by a shear on its right edge ``x = 48`` (Cook, Malkus & Plesha,
Concepts and Applications of Finite Element Analysis, 1989). Its corner ``(48, 60)`` and the
mid-point ``(48, 52)`` of the loaded edge are the usual measuring points; both are mesh nodes
of :func:`cook_membrane` (the loaded edge is two gmsh lines meeting at the mid-point).

>>> from femkit.mesh import generate
>>> m = generate("cook_membrane", 8.0)
>>> round(float(m.volumes().sum()), 9), sorted(m.tag_names)[:3]
(1440.0, ['bottom', 'boundary', 'clamped'])
"""

from __future__ import annotations

from ...validation import mesh_size as _check_h
from ..mesh import Mesh
from .gmsh_session import gmsh_session, mesh_from_gmsh, physical_group, run_mesher, set_size
from .registry import register_geometry

__all__ = ["cook_membrane", "COOK_CORNER", "COOK_MID_EDGE"]

#: the corner of the loaded edge and its mid-point, where Cook's membrane is measured
COOK_CORNER = (48.0, 60.0)
COOK_MID_EDGE = (48.0, 52.0)

_LENGTHS = 44.0 + (48.0 ** 2 + 44.0 ** 2) ** 0.5 + 16.0 + (48.0 ** 2 + 16.0 ** 2) ** 0.5


@register_geometry("cook_membrane", measure=lambda: (1440.0, _LENGTHS),
                   boundary_tags=("clamped", "loaded", "bottom", "top", "boundary"),
                   cell_tags=("domain",))
def cook_membrane(h: float) -> Mesh:
    """Cook's membrane: the quadrilateral panel ``(0, 0)``, ``(48, 44)``, ``(48, 60)``,
    ``(0, 44)`` (area 1440), the origin at its lower clamped corner.

    Edge tags: ``clamped`` (x = 0), ``loaded`` (x = 48; the corner ``(48, 60)`` and the mid-point
    ``(48, 52)`` are nodes), ``bottom`` (from ``(0, 0)`` to ``(48, 44)``), ``top`` (from
    ``(0, 44)`` to ``(48, 60)``), ``boundary`` (all four). Cell tag: ``domain``.
    """
    h = _check_h(h)
    with gmsh_session("cook_membrane") as gmsh:
        geo = gmsh.model.geo
        xy = [(0.0, 0.0), (48.0, 44.0), COOK_MID_EDGE, COOK_CORNER, (0.0, 44.0)]
        pts = [geo.addPoint(x, y, 0.0, h) for x, y in xy]
        lines = [geo.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
        surf = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        geo.synchronize()
        bottom, loaded, top, clamped = [lines[0]], [lines[1], lines[2]], [lines[3]], [lines[4]]
        for k, (name, group) in enumerate((("clamped", clamped), ("loaded", loaded),
                                           ("bottom", bottom), ("top", top)), start=1):
            physical_group(gmsh, 1, group, name, k)
        physical_group(gmsh, 1, lines, "boundary", 5)
        physical_group(gmsh, 2, [surf], "domain", 6)
        gmsh.model.geo.synchronize()
        set_size(gmsh, h)
        run_mesher(gmsh, 2)
        return mesh_from_gmsh(gmsh)
