"""Mesh generation with the gmsh Python API.

gmsh is imported inside the functions only, so ``import femkit.mesh`` stays cheap and a case
that reads a ``.msh`` file never loads it.

Every geometry is one entry of :data:`GEOMETRIES`, a :class:`Geometry` record; call it through
:func:`generate`::

    generate("l_shape", h=0.1)
    generate("annulus", h=0.05, r_inner=0.3, r_outer=1.0)

Adding a geometry is one registration, in any module (nothing else lists geometries: case
files, ``femkit solve``, its cost plan and budget checks all read this registry)::

    def _strip_measure(length=4.0):                 # same parameters and defaults as build
        return length * 1.0, 2.0 * (length + 1.0)   # (area, length of every mesh line)

    @register_geometry("strip", measure=_strip_measure,
                       boundary_tags=("boundary",), cell_tags=("domain",))
    def strip(h, length=4.0):                       # build(h, **params) -> Mesh
        return rectangle(h, 0.0, 0.0, length, 1.0)

An entry holds:

* ``build(h, **params) -> Mesh``: the mesh at target size ``h``;
* ``measure(**params) -> (measure, line_measure)``: with the same parameter names and defaults
  as ``build``; in 2D the area and the length of every mesh line (outer boundary, holes, and
  interfaces between regions counted twice, since the elements on both sides follow them); in
  3D the volume and the area of every mesh surface, counted the same way. The cost model
  predicts the element count from these two numbers (:mod:`femkit.cost.poisson`);
* ``dim``: 2 (triangles) or 3 (tetrahedra);
* ``boundary_tags``, ``cell_tags``: the tag names the generated mesh carries.

Tag conventions (names go to :attr:`Mesh.tag_names`):

* Every geometry tags its whole boundary as the edge group ``"boundary"`` **as well as** named
  parts. An edge in several groups appears once per group in ``Mesh.boundary_edges`` (the same
  node pair repeated with each tag), so ``boundary_edges[boundary_tags == mesh.tag("left")]`` and
  ``boundary_edges[boundary_tags == mesh.tag("boundary")]`` both work.
* Cell groups: single-region geometries tag every triangle ``"domain"``; multi-region geometries
  (``checkerboard``, ``square_with_inclusion``) tag each triangle with its region instead (a
  triangle carries exactly one cell tag).
* Tag numbers are unique across edge and cell groups of a generated mesh.

Generated meshes are deterministic: one gmsh thread, fixed algorithm, no random restarts
between runs; triangles are counter-clockwise.
"""

from __future__ import annotations

import contextlib
import inspect
import math
import os
from dataclasses import dataclass
from typing import Callable, Iterator, Sequence

import numpy as np

from ..errors import InputError, MeshError
from ..registry import Registry
from ..validation import mesh_size as _check_h
from .mesh import Mesh

__all__ = ["GEOMETRIES", "Geometry", "register_geometry", "generate", "geo_file"]


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

#: gmsh element type numbers
_GMSH_LINE, _GMSH_TRIANGLE, _GMSH_TETRA = 1, 2, 4


def _positive(name: str, value) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise InputError(f"{name} must be positive and finite, got {value!r}")
    return v


#: set when a stop request abandoned gmsh's mesher in its thread (see :func:`_generate`)
_ABANDONED: list = []


def _generate(gmsh, dim: int) -> None:
    """``gmsh.model.mesh.generate(dim)``, answering SIGINT/SIGTERM within a fraction of a second
    under :func:`femkit.interrupt.stop_on_signals` (gmsh's C++ mesher never returns to Python
    until done: a large mesh used to hold a Ctrl-C for many seconds)."""
    from ..interrupt import run_interruptible

    run_interruptible(gmsh.model.mesh.generate, dim, what="meshing",
                      on_abandon=lambda: _ABANDONED.append(True))


@contextlib.contextmanager
def _gmsh_session(name: str) -> Iterator[object]:
    """Initialise gmsh quietly (or reuse a live session), yield the module, clean up.

    If gmsh was already initialised by the caller, a fresh model is added and removed again
    and gmsh is left running; otherwise gmsh is finalised on exit, also on errors.
    """
    import gmsh

    owner = not gmsh.isInitialized()
    if owner:
        with _python_signal_handlers():
            gmsh.initialize(argv=[], readConfigFiles=False, run=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.option.setNumber("Mesh.MaxNumThreads2D", 1)
        gmsh.option.setNumber("Mesh.MaxNumThreads3D", 1)
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay
        gmsh.option.setNumber("Mesh.RandomSeed", 1)
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay
        gmsh.option.setNumber("Mesh.ElementOrder", 1)
        gmsh.model.add(name)
        yield gmsh
    finally:
        if _ABANDONED:  # a stop request left the mesher running in its thread: the process is
            pass        # about to exit, and finalising gmsh under it would crash
        elif owner:
            gmsh.finalize()
        else:
            with contextlib.suppress(Exception):
                gmsh.model.remove()


@contextlib.contextmanager
def _python_signal_handlers() -> Iterator[None]:
    """Put Python's SIGINT/SIGTERM handlers back after gmsh's initialisation, which installs
    its own at the C level (a SIGTERM would then kill the process instead of reaching
    :func:`femkit.interrupt.stop_on_signals`)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in saved.items():
            if handler is not None:
                signal.signal(s, handler)


def _set_size(gmsh, h: float) -> None:
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)


def _mesh_from_gmsh(gmsh, dim: int = 2) -> Mesh:
    """Turn the current gmsh model (already meshed in ``dim`` = 2 or 3) into a :class:`Mesh`.

    Cells (triangles in 2D, tetrahedra in 3D): when the model has physical groups of that
    dimension, only cells of entities in a physical group are kept (gmsh's own rule when
    saving), each tagged with its group (the first group when an entity is in several);
    otherwise all cells, tag 0. Facets (edges, triangles) of the physical groups of dimension
    ``dim - 1`` become the tagged boundary. Nodes not used by any kept cell are dropped (e.g.
    circle centres); node order follows gmsh's node tags.
    """
    model = gmsh.model
    cell_code, facet_code = (_GMSH_TRIANGLE, _GMSH_LINE) if dim == 2 else (_GMSH_TETRA, _GMSH_TRIANGLE)
    width = dim + 1
    node_tags, coords, _ = model.mesh.getNodes(-1, -1, includeBoundary=True,
                                               returnParametricCoord=False)
    node_tags = np.asarray(node_tags, dtype=np.int64)
    xyz = np.asarray(coords, dtype=np.float64).reshape(-1, 3)

    def blocks_of(entity_dim: int, ent: int, code: int, w: int):
        types, _, enodes = model.mesh.getElements(entity_dim, ent)
        return [np.asarray(nodes, np.int64).reshape(-1, w) for t, nodes in zip(types, enodes)
                if t == code]

    tri_blocks, tag_blocks = [], []
    names: dict[str, int] = {}
    groups = model.getPhysicalGroups(dim)
    if groups:
        seen_entities: set[int] = set()
        for gdim, ptag in groups:
            name = model.getPhysicalName(gdim, ptag)
            if name:
                names[name] = int(ptag)
            for ent in model.getEntitiesForPhysicalGroup(gdim, ptag):
                if int(ent) in seen_entities:
                    continue
                seen_entities.add(int(ent))
                for b in blocks_of(dim, int(ent), cell_code, width):
                    tri_blocks.append(b)
                    tag_blocks.append(np.full(len(b), ptag, np.int32))
    else:
        for _, ent in model.getEntities(dim):
            for b in blocks_of(dim, ent, cell_code, width):
                tri_blocks.append(b)
                tag_blocks.append(np.zeros(len(b), np.int32))
    if not tri_blocks:
        found = sorted({gmsh.model.mesh.getElementProperties(int(t))[0]
                        for t in model.mesh.getElementTypes(dim)})
        what = "linear triangles" if dim == 2 else "linear tetrahedra"
        raise MeshError(f"gmsh produced no {what}"
                        + (f" (found {dim}D element types: {', '.join(found)})" if found else ""))
    tri_gmsh = np.concatenate(tri_blocks)
    cell_tags = np.concatenate(tag_blocks)

    edge_blocks, etag_blocks = [], []
    for gdim, ptag in model.getPhysicalGroups(dim - 1):
        name = model.getPhysicalName(gdim, ptag)
        if name:
            names[name] = int(ptag)
        for ent in model.getEntitiesForPhysicalGroup(gdim, ptag):
            for b in blocks_of(dim - 1, int(ent), facet_code, dim):
                edge_blocks.append(b)
                etag_blocks.append(np.full(len(b), ptag, np.int32))
    edges_gmsh = np.concatenate(edge_blocks) if edge_blocks else np.zeros((0, dim), np.int64)
    edge_tags = np.concatenate(etag_blocks) if etag_blocks else np.zeros(0, np.int32)

    # compact numbering: keep nodes used by cells, in gmsh tag order
    order = np.argsort(node_tags, kind="stable")
    sorted_tags = node_tags[order]
    used = np.unique(tri_gmsh)
    pos = np.searchsorted(sorted_tags, used)
    if np.any(pos >= len(sorted_tags)) or np.any(sorted_tags[np.minimum(pos, len(sorted_tags) - 1)] != used):
        raise MeshError("gmsh returned cells referring to unknown nodes")
    points = xyz[order[pos], :dim]

    def renumber(arr: np.ndarray) -> np.ndarray:
        idx = np.searchsorted(used, arr)
        idx = np.minimum(idx, len(used) - 1)
        ok = used[idx] == arr
        return idx, ok

    tri, ok = renumber(tri_gmsh)
    e, eok = renumber(edges_gmsh)
    keep = eok.all(axis=1) if len(e) else np.zeros(0, bool)
    from .validate import orient_ccw

    return orient_ccw(Mesh(points=points, cells=tri, cell_tags=cell_tags,
                           boundary_facets=e[keep], boundary_tags=edge_tags[keep],
                           tag_names=names))


def _group(gmsh, dim: int, entities: Sequence[int], name: str, tag: int) -> None:
    gmsh.model.addPhysicalGroup(dim, list(entities), tag)
    gmsh.model.setPhysicalName(dim, tag, name)


def _side_groups(gmsh, left: list[int], right: list[int], bottom: list[int], top: list[int]) -> None:
    """Edge groups 1..5 of a rectangle: left, right, bottom, top and boundary (all four)."""
    for k, (name, lines) in enumerate((("left", left), ("right", right),
                                       ("bottom", bottom), ("top", top)), start=1):
        _group(gmsh, 1, lines, name, k)
    _group(gmsh, 1, left + right + bottom + top, "boundary", 5)


def _finish(gmsh, h: float) -> Mesh:
    gmsh.model.geo.synchronize()
    _set_size(gmsh, h)
    _generate(gmsh, 2)
    return _mesh_from_gmsh(gmsh)


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
    with _gmsh_session("rectangle") as gmsh:
        geo = gmsh.model.geo
        bottom, right, top, left = _polygon(geo, [(x0, y0), (x1, y0), (x1, y1), (x0, y1)], h)
        surf = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, top, left])])
        geo.synchronize()
        _side_groups(gmsh, [left], [right], [bottom], [top])
        _group(gmsh, 2, [surf], "domain", 6)
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
    with _gmsh_session("l_shape") as gmsh:
        geo = gmsh.model.geo
        lines = _polygon(geo, [(-1, -1), (0, -1), (0, 0), (1, 0), (1, 1), (-1, 1)], h)
        surf = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        geo.synchronize()
        reentrant = [lines[1], lines[2]]  # (0,-1)->(0,0) and (0,0)->(1,0)
        outer = [lines[0], lines[3], lines[4], lines[5]]
        _group(gmsh, 1, reentrant, "reentrant", 1)
        _group(gmsh, 1, outer, "outer", 2)
        _group(gmsh, 1, lines, "boundary", 3)
        _group(gmsh, 2, [surf], "domain", 4)
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
    r = _positive("radius", radius)
    cx, cy = map(float, centre)
    with _gmsh_session("disk") as gmsh:
        geo = gmsh.model.geo
        arcs = _circle(geo, cx, cy, r, h)
        surf = geo.addPlaneSurface([geo.addCurveLoop(arcs)])
        geo.synchronize()
        _group(gmsh, 1, arcs, "outer", 1)
        _group(gmsh, 1, arcs, "boundary", 2)
        _group(gmsh, 2, [surf], "domain", 3)
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
    ri, ro = _positive("r_inner", r_inner), _positive("r_outer", r_outer)
    if not ri < ro:
        raise InputError(f"annulus needs r_inner < r_outer, got {ri} and {ro}")
    cx, cy = map(float, centre)
    with _gmsh_session("annulus") as gmsh:
        geo = gmsh.model.geo
        outer = _circle(geo, cx, cy, ro, h)
        inner = _circle(geo, cx, cy, ri, h)
        surf = geo.addPlaneSurface([geo.addCurveLoop(outer), geo.addCurveLoop(inner)])
        geo.synchronize()
        _group(gmsh, 1, inner, "inner", 1)
        _group(gmsh, 1, outer, "outer", 2)
        _group(gmsh, 1, outer + inner, "boundary", 3)
        _group(gmsh, 2, [surf], "domain", 4)
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
    with _gmsh_session("checkerboard") as gmsh:
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
        _group(gmsh, 2, high, "high", 6)
        _group(gmsh, 2, low, "low", 7)
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
    r = _positive("radius", radius)
    cx, cy = map(float, centre)
    if shape not in ("disk", "square"):
        raise InputError(f"inclusion shape must be 'disk' or 'square', got {shape!r}")
    if not (cx - r > 0 and cx + r < 1 and cy - r > 0 and cy + r < 1):
        raise InputError(f"inclusion (centre {centre}, radius {r}) must lie strictly inside the unit square")
    with _gmsh_session("square_with_inclusion") as gmsh:
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
        _group(gmsh, 2, [matrix], "matrix", 6)
        _group(gmsh, 2, [inclusion], "inclusion", 7)
        return _finish(gmsh, h)


def geo_file(path: str | os.PathLike, h: float | None = None) -> Mesh:
    """Mesh a user ``.geo`` file with gmsh (physical groups become tags): in 3D when it defines
    volumes (tetrahedra; physical surfaces become the tagged faces), else in 2D.

    Parameters
    ----------
    path : path to the ``.geo`` (or any file gmsh can open)
    h : optional maximal mesh size; ``None`` keeps the sizes the file sets.

    Tags come only from the file's physical groups (no ``"boundary"`` group is added): with
    2D physical groups only their triangles are kept (gmsh's saving rule), without any all
    triangles are kept with cell tag 0.

    Raises
    ------
    MeshError
        The file is missing, gmsh cannot open it or produces no triangles.
    """
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise MeshError(f"geometry file not found: {p}")
    hv = None if h is None else _check_h(h)
    with _gmsh_session("geo_file") as gmsh:
        try:
            gmsh.open(p)
            if hv is not None:
                gmsh.option.setNumber("Mesh.MeshSizeMax", hv)
            gmsh.option.setNumber("Mesh.ElementOrder", 1)
            dim = 3 if gmsh.model.getEntities(3) else 2
            _generate(gmsh, dim)
        except Exception as exc:  # gmsh raises bare Exception with its last error
            raise MeshError(f"gmsh could not mesh {p}: {exc}") from None
        if dim == 3:
            _refuse_unassigned_volumes(gmsh, p)
        return _mesh_from_gmsh(gmsh, dim)


def _refuse_unassigned_volumes(gmsh, path: str) -> None:
    """A .geo with physical volumes that leave a volume out would lose its tetrahedra
    silently (gmsh's saving rule): refuse it in one line."""
    groups = gmsh.model.getPhysicalGroups(3)
    if not groups:
        return
    grouped = {int(e) for _, t in groups for e in gmsh.model.getEntitiesForPhysicalGroup(3, t)}
    loose = sorted(int(t) for _, t in gmsh.model.getEntities(3) if int(t) not in grouped)
    if loose:
        raise MeshError(f"{path}: volume(s) {', '.join(map(str, loose))} belong to no physical "
                        "volume; add them to a Physical Volume (gmsh would drop their tetrahedra)")


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

