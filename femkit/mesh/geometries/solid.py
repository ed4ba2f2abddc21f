"""Solid geometries (tetrahedral meshes) of the :data:`~femkit.mesh.geometries.GEOMETRIES` registry.

Built with gmsh's OpenCASCADE kernel and meshed in 3D (Delaunay, one thread, deterministic).
Tag conventions as in 2D: the whole boundary is the face group ``"boundary"`` **as well as**
named parts (a face in several groups appears once per group in ``Mesh.boundary_facets``);
every tetrahedron carries the cell group ``"domain"``. The volume of each geometry is plain
from its parameters (``box``: ``lx ly lz``; ``l_shape_3d``: 7; ``sphere``: ``4/3 pi r^3``;
``cylinder``: ``pi r^2 height``).

>>> from femkit.mesh import generate
>>> m = generate("unit_cube", 0.5)
>>> m.dim, round(float(m.volumes().sum()), 12), sorted(m.tag_names)[:3]
(3, 1.0, ['boundary', 'domain', 'xmax'])
"""

from __future__ import annotations

import math
from typing import Sequence

from ...errors import InputError
from ...validation import mesh_size as _check_h
from ..mesh import Mesh
from .gmsh_session import gmsh_session, mesh_from_gmsh, physical_group, run_mesher, set_size
from .registry import positive, register_geometry

_SIDES = ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax")


def _finish3d(gmsh, h: float) -> Mesh:
    gmsh.model.occ.synchronize()
    set_size(gmsh, h)
    run_mesher(gmsh, 3)
    return mesh_from_gmsh(gmsh, dim=3)


def _surfaces_by_box(gmsh) -> dict[int, tuple[float, ...]]:
    """Bounding box ``(xmin, ymin, zmin, xmax, ymax, zmax)`` of every surface of the model."""
    return {tag: gmsh.model.getBoundingBox(2, tag) for _, tag in gmsh.model.getEntities(2)}


def _box_groups(gmsh, lo: Sequence[float], hi: Sequence[float], first_tag: int = 1) -> int:
    """Face groups xmin..zmax (planar sides of an axis-aligned box) + boundary; returns the
    next free tag."""
    tol = 1e-5 * max(hi[d] - lo[d] for d in range(3))  # OCC pads bounding boxes by ~1e-7
    boxes = _surfaces_by_box(gmsh)
    tag = first_tag
    for k, name in enumerate(_SIDES):
        d, upper = divmod(k, 2)
        plane = hi[d] if upper else lo[d]
        faces = [s for s, b in boxes.items() if abs(b[d] - plane) < tol and abs(b[d + 3] - plane) < tol]
        physical_group(gmsh, 2, faces, name, tag)
        tag += 1
    physical_group(gmsh, 2, list(boxes), "boundary", tag)
    return tag + 1


@register_geometry("box", dim=3, measure=lambda lx=1.0, ly=1.0, lz=1.0, origin=(0.0, 0.0, 0.0): (
    lx * ly * lz, 2 * (lx * ly + ly * lz + lz * lx)), boundary_tags=('xmin', 'xmax', 'ymin', 'ymax', 'zmin', 'zmax', 'boundary'), cell_tags=("domain",))
def box(h: float, lx: float = 1.0, ly: float = 1.0, lz: float = 1.0,
        origin: Sequence[float] = (0.0, 0.0, 0.0)) -> Mesh:
    """Box ``[x0, x0 + lx] x [y0, y0 + ly] x [z0, z0 + lz]``, ``(x0, y0, z0) = origin`` (volume
    ``lx ly lz``).

    Face tags: ``xmin`` (x = x0), ``xmax`` (x = x0 + lx), ``ymin``, ``ymax``, ``zmin``, ``zmax``
    likewise, ``boundary`` (all six). Cell tag: ``domain``.
    """
    h = _check_h(h)
    lx, ly, lz = (positive(n, v) for n, v in (("lx", lx), ("ly", ly), ("lz", lz)))
    x0, y0, z0 = map(float, origin)
    with gmsh_session("box") as gmsh:
        vol = gmsh.model.occ.addBox(x0, y0, z0, lx, ly, lz)
        gmsh.model.occ.synchronize()
        nxt = _box_groups(gmsh, (x0, y0, z0), (x0 + lx, y0 + ly, z0 + lz))
        physical_group(gmsh, 3, [vol], "domain", nxt)
        return _finish3d(gmsh, h)


@register_geometry("unit_cube", dim=3, measure=lambda: (1.0, 6.0), boundary_tags=('xmin', 'xmax', 'ymin', 'ymax', 'zmin', 'zmax', 'boundary'),
                   cell_tags=("domain",))
def unit_cube(h: float) -> Mesh:
    """Unit cube ``[0, 1]^3``, the origin at a corner.

    Face tags: ``xmin`` (x = 0), ``xmax`` (x = 1), ``ymin``, ``ymax``, ``zmin``, ``zmax``
    likewise, ``boundary`` (all six). Cell tag: ``domain``.
    """
    return box(h, 1.0, 1.0, 1.0)


@register_geometry("beam", dim=3, measure=lambda length=5.0, width=1.0, height=1.0: (
    length * width * height, 2 * (length * width + width * height + height * length)),
    boundary_tags=("xmin", "xmax", "ymin", "ymax", "zmin", "zmax", "boundary", "clamped", "tip"),
    cell_tags=("domain",))
def beam(h: float, length: float = 5.0, width: float = 1.0, height: float = 1.0) -> Mesh:
    """Beam ``[0, length] x [0, width] x [0, height]``: its axis along x, the origin at a corner of
    the clamped end (volume ``length width height``).

    Face tags: ``xmin`` (x = 0), ``xmax`` (x = length), ``ymin`` (y = 0), ``ymax`` (y = width),
    ``zmin`` (z = 0), ``zmax`` (z = height), ``boundary`` (all six), and ``clamped`` (x = 0, the
    same faces as ``xmin``) and ``tip`` (x = length, as ``xmax``). Cell tag: ``domain``.
    """
    h = _check_h(h)
    L, W, H = (positive(n, v) for n, v in (("length", length), ("width", width), ("height", height)))
    with gmsh_session("beam") as gmsh:
        vol = gmsh.model.occ.addBox(0.0, 0.0, 0.0, L, W, H)
        gmsh.model.occ.synchronize()
        nxt = _box_groups(gmsh, (0.0, 0.0, 0.0), (L, W, H))
        boxes = _surfaces_by_box(gmsh)
        tol = 1e-5 * L
        physical_group(gmsh, 2, [s for s, b in boxes.items() if abs(b[3]) < tol], "clamped", nxt)
        physical_group(gmsh, 2, [s for s, b in boxes.items() if abs(b[0] - L) < tol], "tip", nxt + 1)
        physical_group(gmsh, 3, [vol], "domain", nxt + 2)
        return _finish3d(gmsh, h)


@register_geometry("l_shape_3d", dim=3, measure=lambda: (7.0, 24.0),
                   boundary_tags=("reentrant", "outer", "boundary"), cell_tags=("domain",))
def l_shape_3d(h: float) -> Mesh:
    """Fichera corner: the cube ``(-1, 1)^3`` minus the octant ``[0, 1]^3`` (volume 7).

    The re-entrant vertex is the origin. Face tags: ``reentrant`` (the three faces of the
    removed octant), ``outer`` (the rest), ``boundary`` (all). Cell tag: ``domain``.
    """
    h = _check_h(h)
    with gmsh_session("l_shape_3d") as gmsh:
        occ = gmsh.model.occ
        cube = occ.addBox(-1.0, -1.0, -1.0, 2.0, 2.0, 2.0)
        octant = occ.addBox(0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
        out, _ = occ.cut([(3, cube)], [(3, octant)])
        occ.synchronize()
        boxes = _surfaces_by_box(gmsh)
        inner = [s for s, b in boxes.items() if min(b[:3]) > -1e-5]
        outer = [s for s in boxes if s not in inner]
        physical_group(gmsh, 2, inner, "reentrant", 1)
        physical_group(gmsh, 2, outer, "outer", 2)
        physical_group(gmsh, 2, list(boxes), "boundary", 3)
        physical_group(gmsh, 3, [t for _, t in out], "domain", 4)
        return _finish3d(gmsh, h)


@register_geometry("sphere", dim=3, measure=lambda radius=1.0, centre=(0.0, 0.0, 0.0): (
    4.0 / 3.0 * math.pi * radius ** 3, 4.0 * math.pi * radius ** 2),
    boundary_tags=("outer", "boundary"), cell_tags=("domain",))
def sphere(h: float, radius: float = 1.0, centre: Sequence[float] = (0.0, 0.0, 0.0)) -> Mesh:
    """Ball of ``radius`` about ``centre`` (volume ``4/3 pi radius^3``; the mesh's is smaller by
    the faceting, O(h^2)).

    Face tags: ``outer`` and ``boundary`` (the same faces). Cell tag: ``domain``.
    """
    h = _check_h(h)
    r = positive("radius", radius)
    cx, cy, cz = map(float, centre)
    with gmsh_session("sphere") as gmsh:
        vol = gmsh.model.occ.addSphere(cx, cy, cz, r)
        gmsh.model.occ.synchronize()
        faces = list(_surfaces_by_box(gmsh))
        physical_group(gmsh, 2, faces, "outer", 1)
        physical_group(gmsh, 2, faces, "boundary", 2)
        physical_group(gmsh, 3, [vol], "domain", 3)
        return _finish3d(gmsh, h)


@register_geometry("cylinder", dim=3, measure=lambda radius=0.5, height=1.0: (
    math.pi * radius ** 2 * height, 2 * math.pi * radius * (radius + height)),
    boundary_tags=("bottom", "top", "side", "boundary"), cell_tags=("domain",))
def cylinder(h: float, radius: float = 0.5, height: float = 1.0) -> Mesh:
    """Cylinder of ``radius`` about the z axis, ``0 <= z <= height`` (volume ``pi radius^2
    height``).

    Face tags: ``bottom`` (z = 0), ``top`` (z = height), ``side``, ``boundary``. Cell tag:
    ``domain``.
    """
    h = _check_h(h)
    r, H = positive("radius", radius), positive("height", height)
    if not math.isfinite(r * H):
        raise InputError(f"cylinder: radius and height must be finite, got {radius}, {height}")
    with gmsh_session("cylinder") as gmsh:
        vol = gmsh.model.occ.addCylinder(0.0, 0.0, 0.0, 0.0, 0.0, H, r)
        gmsh.model.occ.synchronize()
        boxes = _surfaces_by_box(gmsh)
        tol = 1e-5 * max(r, H)
        bottom = [s for s, b in boxes.items() if abs(b[5]) < tol]
        top = [s for s, b in boxes.items() if abs(b[2] - H) < tol]
        side = [s for s in boxes if s not in bottom + top]
        physical_group(gmsh, 2, bottom, "bottom", 1)
        physical_group(gmsh, 2, top, "top", 2)
        physical_group(gmsh, 2, side, "side", 3)
        physical_group(gmsh, 2, list(boxes), "boundary", 4)
        physical_group(gmsh, 3, [vol], "domain", 5)
        return _finish3d(gmsh, h)
