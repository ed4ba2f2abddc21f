"""System types a scene file can declare (``system: {type: ...}``): the registry :data:`SYSTEMS`.

Each entry is a :class:`SystemType`: the JSON schema of its ``system`` mapping and the builder
of the :class:`~femkit.dynamics.system.MassSpringSystem`. The scene schema's ``system.type``
enum and per-type branches are derived from this registry. Builders import the dynamics and
mesh layers when called.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from ...registry import Registry
from ..fragments import COUNT2, DIM, NODES, NONNEG, POS, VEC, closed, pinned

__all__ = ["SystemType", "SystemSize", "SYSTEMS", "COMMON", "system_size"]


@dataclass(frozen=True)
class SystemType:
    """One kind of particle system.

    ``schema``: the JSON schema of its ``system`` mapping (``type``, ``damping`` and
    ``velocity`` included: start from :data:`COMMON`); ``build(params, origin, kw) -> (system,
    triangles or None[, notes])`` (notes: lines the run prints, e.g. a mesh file's dropped nodes) where ``params`` is the mapping without ``type``, ``velocity``,
    ``damping`` and ``origin`` (a copy the builder may consume) and ``kw`` holds ``forces`` and
    ``damping`` for the system's constructor. ``size(system mapping) -> SystemSize`` counts
    nodes and springs from the numbers of the mapping alone, allocating nothing: the cost plan
    prices a scene with it before :attr:`build` runs (``None``: priced after building).
    """

    schema: dict
    build: Callable[[dict, Any, dict], tuple]
    size: Callable[[Any], "SystemSize"] | None = None


@dataclass(frozen=True)
class SystemSize:
    """A system's size from its file's numbers: ``nodes``, ``springs``, ``dim``, and for a mesh
    system the mesh it needs (``mesh``: keywords of :func:`femkit.cost.plan_mesh`, else None)."""

    nodes: float
    springs: float
    dim: int
    mesh: dict | None = None


#: system type -> :class:`SystemType`
SYSTEMS: Registry = Registry("system type")

#: Initial velocity: a constant vector, or one expression string of ``x, y, z`` per component.
VELOCITY = {
    "type": "array", "minItems": 2, "maxItems": 3,
    "items": {"anyOf": [{"type": "number"}, {"type": "string", "minLength": 1}],
              "x-message": "expected a number or an expression string of x, y, z"},
}

#: Keys every system mapping has (the dashpot coefficient along every spring, the velocity).
COMMON = {"type": {"type": "string"}, "damping": NONNEG, "velocity": VELOCITY}


def _rope(s: dict, origin, kw: dict):
    from ...dynamics import topology

    return topology.rope(s.pop("n"), s.pop("length"), origin=origin, **s, **kw), None


def _cloth(s: dict, origin, kw: dict):
    from ...dynamics import topology
    from ...mesh import grid_triangles

    nx, ny = s.pop("nx"), s.pop("ny")
    system = topology.cloth_grid(nx, ny, s.pop("width"), s.pop("height"), origin=origin, **s, **kw)
    return system, grid_triangles(nx, ny)


def scene_mesh(spec: dict, notes: list | None = None):
    """The validated mesh of a ``type: mesh`` system (generated or read); a file's unused nodes
    are dropped with a note appended to ``notes`` (as for a Poisson case's mesh file)."""
    from ...errors import InputError, with_prefix
    from ...mesh import generate, read_mesh, validate
    from ...mesh.validate import drop_unreferenced
    from ..cost import check_mesh_fits

    where = f"system.file {spec['file']}" if "file" in spec else f"system.geometry {spec['geometry']}"
    try:
        if "file" in spec:
            mesh, note = drop_unreferenced(read_mesh(spec["file"], compact=False))
            if note and notes is not None:
                notes.append(f"system.file: {note}")
            return validate(mesh)
        params = spec.get("params") or {}
        check_mesh_fits(geometry=spec["geometry"], h=spec["h"], params=params)
        return validate(generate(spec["geometry"], spec["h"], **params))
    except InputError as exc:
        raise with_prefix(exc, where) from None


def _mesh(s: dict, origin, kw: dict):
    import numpy as np

    from ...dynamics import topology

    notes: list[str] = []
    mesh = scene_mesh(s, notes)
    for key in ("geometry", "h", "params", "file"):
        s.pop(key, None)
    system = topology.mesh_springs(mesh, **s, **kw)
    if origin is not None:
        system.x0 = system.x0 + np.asarray(origin, float).reshape(1, system.dim)
    return system, np.asarray(mesh.triangles, dtype=np.int64), notes


def _rope_size(s) -> SystemSize:
    return SystemSize(int(s["n"]), int(s["n"]) - 1, int(s.get("dim", 2)))


def _cloth_size(s) -> SystemSize:
    """Counts of :func:`femkit.dynamics.topology.grid_springs`, families of zero stiffness left out."""
    nx, ny = int(s["nx"]), int(s["ny"])
    springs = (nx - 1) * ny + nx * (ny - 1)
    if s.get("k_shear"):
        springs += 2 * (nx - 1) * (ny - 1)
    if s.get("k_bending"):
        springs += max(nx - 2, 0) * ny + nx * max(ny - 2, 0)
    return SystemSize(nx * ny, springs, int(s.get("dim", 3)))


def _mesh_size(s) -> SystemSize:
    """Triangles from the geometry's measure and ``h`` (gmsh's model, :func:`femkit.cost.
    predict_triangles`) or the mesh file's header; a triangulation of ``T`` triangles has about
    ``T / 2`` nodes and ``3 T / 2`` edges (Euler's formula, boundary neglected)."""
    from ...cost import msh_triangle_count, predict_triangles
    from ..cost import geometry_domain

    if "file" in s:
        triangles = float(msh_triangle_count(s["file"])[0])
        mesh = dict(triangles=triangles)
    else:
        dim, area, length = geometry_domain(s["geometry"], s.get("params"))
        if dim != 2:
            return None
        triangles = predict_triangles(area, length, s["h"])
        mesh = dict(area=area, line_length=length, h=s["h"], name=s["geometry"],
                    params=dict(s.get("params") or {}))
    return SystemSize(triangles / 2.0 + 1.0, 1.5 * triangles, int(s.get("dim", 2)), mesh)


def system_size(system) -> SystemSize | None:
    """The size of a validated ``system`` mapping, by its type's ``size`` (None: not countable
    before building)."""
    size = SYSTEMS.get(system["type"]).size
    return None if size is None else size(system)


def _single_spring(s: dict, origin, kw: dict):
    from ...dynamics import topology

    return topology.single_spring(s.pop("k"), s.pop("m"), s.pop("rest", 1.0), gravity=None,
                                  **s, **kw), None


SYSTEMS.register("rope", SystemType(closed({
    **COMMON,
    "origin": VEC, "n": COUNT2, "length": POS, "k": POS, "mass": POS, "total_mass": POS, "dim": DIM,
    "pinned": pinned(["first", "last", "both", "none"]),
}, ["type", "n", "length", "k"]), _rope, _rope_size))

SYSTEMS.register("cloth", SystemType(closed({
    **COMMON,
    "origin": VEC, "nx": COUNT2, "ny": COUNT2, "width": POS, "height": POS,
    "k_structural": POS, "k_shear": NONNEG, "k_bending": NONNEG,
    "mass": POS, "total_mass": POS, "plane": {"enum": ["xz", "xy"]}, "dim": DIM,
    "pinned": pinned(["top_corners", "corners", "top_edge", "none"]),
}, ["type", "nx", "ny", "width", "height", "k_structural"]), _cloth, _cloth_size))

SYSTEMS.register("mesh", SystemType({
    **closed({
        **COMMON,
        "origin": VEC, "geometry": {"type": "string", "minLength": 1}, "h": POS,
        "params": {"type": "object"}, "file": {"type": "string", "minLength": 1},
        "k": POS, "density": POS, "thickness": POS, "dim": DIM,
        "pinned": {"anyOf": [{"type": "string", "minLength": 1}, NODES],
                   "x-message": "expected a boundary tag name or a list of node indices"},
    }, ["type", "k"]),
    "oneOf": [{"required": ["geometry", "h"]}, {"required": ["file"]}],
    "x-message": "give either 'geometry' with 'h' (generated mesh) or 'file' (read mesh), not both",
}, _mesh, _mesh_size))

SYSTEMS.register("single_spring", SystemType(closed({
    **COMMON,
    "k": POS, "m": POS, "rest": POS, "dim": DIM,
}, ["type", "k", "m"]), _single_spring,
    lambda s: SystemSize(2, 1, int(s.get("dim", 2)))))
