"""Builders of mass-spring systems: rope, cloth grid, springs on a triangle mesh, SOFA's single spring.

Every builder returns a :class:`~femkit.dynamics.system.MassSpringSystem`; extra keyword
arguments (``damping``, ``v0``, ``forces``) go to its constructor. Spring lists are built with
numpy index arithmetic (no loop over nodes).

Spring families (``system.family`` holds the codes, :data:`FAMILIES` their names):
``0`` structural (grid neighbours), ``1`` shear (diagonals), ``2`` bending (skip one node),
``3`` edge (mesh edges and rope links).

>>> c = cloth_grid(4, 3, 3.0, 2.0, k_structural=10.0, k_shear=5.0, k_bending=1.0)
>>> np.bincount(c.family).tolist()        # 3*3 + 4*2 structural, 2*3*2 shear, 2*3 + 4*1 bending
[17, 12, 10]
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, MeshError
from .forces.gravity import Gravity
from .system import MassSpringSystem

__all__ = ["FAMILIES", "rope", "cloth_grid", "mesh_springs", "single_spring", "mesh_edges"]

FAMILIES = ("structural", "shear", "bending", "edge")
STRUCTURAL, SHEAR, BENDING, EDGE = range(4)


def _count(value, name, minimum):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise InputError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _positive(value, name):
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(f) or f <= 0.0:
        raise InputError(f"{name} must be finite and > 0, got {value!r}")
    return f


def _masses(n, mass, total_mass):
    if total_mass is not None:
        if mass is not None:
            raise InputError("give either mass (per node) or total_mass, not both")
        return _positive(total_mass, "total_mass") / n
    return 1.0 if mass is None else mass


def rope(n: int, length: float, *, dim: int = 2, k: float, mass=None, total_mass=None,
         pinned="first", origin=None, **kwargs) -> MassSpringSystem:
    """A chain of ``n`` particles along ``+x`` from ``origin``, ``n - 1`` springs at rest.

    Parameters
    ----------
    n : number of particles (>= 2).
    length : total rest length.
    dim : 2 or 3.
    k : spring stiffness.
    mass, total_mass : per-node mass (default 1) or total mass shared equally.
    pinned : ``"first"``, ``"last"``, ``"both"``, ``"none"`` or node indices.

    >>> r = rope(5, 2.0, k=10.0)
    >>> r.n_springs, r.rest.tolist(), r.pinned.nonzero()[0].tolist()
    (4, [0.5, 0.5, 0.5, 0.5], [0])
    """
    n = _count(n, "rope n", 2)
    length = _positive(length, "rope length")
    if dim not in (2, 3):
        raise InputError(f"dim must be 2 or 3, got {dim!r}")
    x0 = np.zeros((n, dim))
    x0[:, 0] = np.linspace(0.0, length, n)
    if origin is not None:
        x0 += np.asarray(origin, dtype=float).reshape(1, dim)
    springs = np.stack([np.arange(n - 1), np.arange(1, n)], axis=1)
    named = {"first": [0], "last": [n - 1], "both": [0, n - 1], "none": []}
    if isinstance(pinned, str):
        if pinned not in named:
            raise InputError(f"rope pinned must be one of {sorted(named)} or indices, got {pinned!r}")
        pinned = np.array(named[pinned], dtype=np.intp)
    return MassSpringSystem(x0, _masses(n, mass, total_mass), springs, k, pinned=pinned,
                            family=np.full(n - 1, EDGE), **kwargs)


def grid_springs(nx: int, ny: int):
    """Structural, shear and bending springs of an ``nx x ny`` grid (node ``r*nx + c``).

    Returns ``(springs (s, 2), family (s,))``. Counts: structural ``(nx-1) ny + nx (ny-1)``,
    shear ``2 (nx-1)(ny-1)``, bending ``(nx-2) ny + nx (ny-2)``.
    """
    idx = np.arange(nx * ny).reshape(ny, nx)

    def pairs(a, b):
        return np.stack([a.ravel(), b.ravel()], axis=1)

    fam = [
        (STRUCTURAL, pairs(idx[:, :-1], idx[:, 1:])),
        (STRUCTURAL, pairs(idx[:-1, :], idx[1:, :])),
        (SHEAR, pairs(idx[:-1, :-1], idx[1:, 1:])),
        (SHEAR, pairs(idx[:-1, 1:], idx[1:, :-1])),
        (BENDING, pairs(idx[:, :-2], idx[:, 2:])),
        (BENDING, pairs(idx[:-2, :], idx[2:, :])),
    ]
    springs = np.concatenate([p for _, p in fam]).astype(np.intp)
    family = np.concatenate([np.full(len(p), f) for f, p in fam])
    return springs, family


def cloth_grid(nx: int, ny: int, width: float, height: float, *, k_structural: float,
               k_shear: float | None = None, k_bending: float | None = None, mass=None,
               total_mass=None, pinned="top_corners", plane: str = "xz", dim: int = 3,
               origin=None, **kwargs) -> MassSpringSystem:
    """A rectangular cloth of ``nx x ny`` particles with structural, shear and bending springs.

    Parameters
    ----------
    nx, ny : particles along the width and the height (>= 2 each).
    width, height : cloth size.
    k_structural, k_shear, k_bending : stiffness of each family; a family whose stiffness
        is ``None`` or 0 is left out.
    mass, total_mass : per-node mass (default 1) or total mass shared equally.
    pinned : ``"top_corners"`` (the two corners of the last row), ``"corners"`` (all four),
        ``"top_edge"`` (the whole last row), ``"none"`` or node indices.
    plane : ``"xz"`` hanging vertically (row ``r`` at ``z = r h/(ny-1)``, ``y = 0``; gravity
        along ``-z`` by default) or ``"xy"`` horizontal (``z = 0``, or the 2D plane for ``dim=2``).
    dim : 3, or 2 with ``plane="xy"``.

    Node ``r*nx + c`` sits at column ``c`` (``x = c width/(nx-1)``) and row ``r``.
    """
    nx = _count(nx, "cloth nx", 2)
    ny = _count(ny, "cloth ny", 2)
    width = _positive(width, "cloth width")
    height = _positive(height, "cloth height")
    if plane not in ("xz", "xy"):
        raise InputError(f"cloth plane must be 'xz' or 'xy', got {plane!r}")
    if dim not in (2, 3) or (dim == 2 and plane != "xy"):
        raise InputError(f"cloth dim must be 3, or 2 with plane='xy'; got dim={dim!r}, plane={plane!r}")
    n = nx * ny
    cx = np.tile(np.linspace(0.0, width, nx), ny)
    ry = np.repeat(np.linspace(0.0, height, ny), nx)
    x0 = np.zeros((n, dim))
    x0[:, 0] = cx
    x0[:, 2 if plane == "xz" else 1] = ry
    if origin is not None:
        x0 += np.asarray(origin, dtype=float).reshape(1, dim)

    springs, family = grid_springs(nx, ny)
    stiff = np.array([k_structural, k_shear or 0.0, k_bending or 0.0], dtype=float)
    if stiff[0] <= 0.0:
        raise InputError(f"k_structural must be > 0, got {k_structural!r}")
    keep = stiff[family] > 0.0
    springs, family = springs[keep], family[keep]

    top = (ny - 1) * nx
    named = {"top_corners": [top, n - 1], "corners": [0, nx - 1, top, n - 1],
             "top_edge": list(range(top, n)), "none": []}
    if isinstance(pinned, str):
        if pinned not in named:
            raise InputError(f"cloth pinned must be one of {sorted(named)} or indices, got {pinned!r}")
        pinned = np.array(named[pinned], dtype=np.intp)
    return MassSpringSystem(x0, _masses(n, mass, total_mass), springs, stiff[family], pinned=pinned,
                            family=family, **kwargs)


def mesh_edges(triangles: np.ndarray) -> np.ndarray:
    """Unique undirected edges ``(e, 2)`` (sorted pairs) of a triangle array.

    >>> mesh_edges(np.array([[0, 1, 2], [2, 1, 3]])).tolist()
    [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]
    """
    t = np.asarray(triangles)
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    e.sort(axis=1)
    return np.unique(e, axis=0).astype(np.intp)


def mesh_springs(mesh, *, k: float, density: float = 1.0, thickness: float = 1.0, dim: int = 2,
                 pinned=None, **kwargs) -> MassSpringSystem:
    """Springs on the unique edges of a femkit triangle mesh (a soft body from any gmsh geometry).

    Masses are lumped: each triangle gives ``density * thickness * area / 3`` to each vertex,
    so they sum to ``density * thickness * total area``. Rest lengths are the mesh edge lengths.

    Parameters
    ----------
    mesh : femkit.mesh.Mesh
    k : spring stiffness (scalar or one per unique edge, in :func:`mesh_edges` order).
    density, thickness : areal mass is ``density * thickness``.
    dim : 2, or 3 (the mesh embedded in the plane ``z = 0``).
    pinned : node indices, a boolean mask, or a boundary group name of the mesh.

    Raises
    ------
    MeshError
        Nodes that no triangle references (they would get no mass).
    """
    if dim not in (2, 3):
        raise InputError(f"dim must be 2 or 3, got {dim!r}")
    rho = _positive(density, "density") * _positive(thickness, "thickness")
    tri = mesh.triangles
    area = mesh.areas()
    mass = np.bincount(tri.ravel(), weights=np.repeat(rho * area / 3.0, 3), minlength=mesh.n_points)
    lonely = np.flatnonzero(mass <= 0.0)
    if len(lonely):
        raise MeshError(f"mesh nodes {lonely[:5].tolist()} belong to no triangle of positive area, "
                        "so they get no mass")
    x0 = np.zeros((mesh.n_points, dim))
    x0[:, :2] = mesh.points
    if isinstance(pinned, str):
        tag = mesh.tag(pinned)
        pinned = np.unique(mesh.boundary_edges[mesh.boundary_tags == tag])
    edges = mesh_edges(tri)
    return MassSpringSystem(x0, mass, edges, k, pinned=pinned, family=np.full(len(edges), EDGE), **kwargs)


def single_spring(k: float = 100.0, m: float = 10.0, rest: float = 1.0, *, gravity: float | None = 10.0,
                  dim: int = 2, **kwargs) -> MassSpringSystem:
    """SOFA's ODE-solver test scene: node 0 fixed at ``y = 2``, node 1 (mass ``m``) at ``y = 1``.

    The spring (stiffness ``k``, rest length ``rest``, default 1) starts at rest; gravity of
    magnitude ``gravity`` pulls along ``-y`` (``None`` or 0: no gravity). With the SOFA values
    ``k = 100, m = 10, g = 10`` the equilibrium is ``y = 1 - m g / k = 0``, so
    ``y(t) = cos(sqrt(k/m) t)``.

    >>> s = single_spring()
    >>> s.x0.tolist(), s.mass.tolist(), s.pinned.tolist()
    ([[0.0, 2.0], [0.0, 1.0]], [10.0, 10.0], [True, False])
    """
    if dim not in (2, 3):
        raise InputError(f"dim must be 2 or 3, got {dim!r}")
    x0 = np.zeros((2, dim))
    x0[:, 1] = [2.0, 1.0]
    forces = list(kwargs.pop("forces", ()))
    if gravity:
        forces.insert(0, Gravity(gravity, axis=1))
    return MassSpringSystem(x0, m, [[0, 1]], k, rest=rest, pinned=[0], forces=forces, **kwargs)
