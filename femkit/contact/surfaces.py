"""Contact surfaces: a body's boundary and the obstacles a scene declares.

Every surface is plain arrays: ``vertices`` ``(m, d)`` and ``faces`` ``(k, 3)`` triangles in 3D or
``(k, 2)`` segments in 2D. A body's contact surface is made from its cells
(:func:`body_surface`): the boundary triangles of tetrahedra, the boundary segments of triangles
in the plane, or the triangles themselves of a surface (cloth) in 3D. Obstacles are surfaces,
static or in a prescribed rigid motion (:class:`Motion`: a constant velocity or a keyframed
path, and a constant angular velocity about a pivot): a plane (a square, or a segment in 2D,
large enough for the scene), a sphere (a subdivided icosahedron, or a polygon in 2D) and a
surface mesh read from a file by meshio (``.msh``, ``.stl``, ``.obj``; triangles, or lines in
2D).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import InputError

__all__ = ["Obstacle", "Motion", "rotation", "body_surface", "plane_obstacle", "sphere_obstacle",
           "file_obstacle"]


def rotation(omega, t: float) -> np.ndarray:
    """The rotation matrix of a constant angular velocity ``omega`` after time ``t``: in 2D
    ``omega`` is a rate (rad/s, counter-clockwise), in 3D a vector (axis times rate; Rodrigues'
    formula ``I + sin(a) K + (1 - cos(a)) K^2`` with ``a = |omega| t``, ``K`` the cross-product
    matrix of the unit axis).

    >>> np.round(rotation(np.pi / 2, 1.0) @ [1.0, 0.0], 12).tolist()
    [0.0, 1.0]
    >>> np.round(rotation([0.0, 0.0, np.pi], 0.5) @ [1.0, 0.0, 0.0], 12).tolist()
    [0.0, 1.0, 0.0]
    """
    w = np.asarray(omega, dtype=float)
    if w.ndim == 0:
        a = float(w) * t
        return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    rate = float(np.linalg.norm(w))
    if rate == 0.0:
        return np.eye(3)
    k = w / rate
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    a = rate * t
    return np.eye(3) + np.sin(a) * K + (1.0 - np.cos(a)) * (K @ K)


@dataclass(frozen=True)
class Motion:
    """A prescribed rigid motion: ``x(t) = p + u(t) + R(t) (x0 - p)``.

    The translation ``u(t)`` is ``t velocity``, or the piecewise-linear interpolation of a
    ``path`` of keyframes ``(t_k, u_k)`` (held at its first value before the first key and at
    its last after the last); ``R(t)`` turns at the constant ``angular_velocity`` about the pivot
    ``p`` (:func:`rotation`), which travels with the translation.

    Attributes
    ----------
    velocity : (d,) float array, optional
    path : (k, 1 + d) float array, optional
        Rows ``[t, u_1, ..., u_d]``, times strictly increasing (not with ``velocity``).
    angular_velocity : float (2D) or (3,) float array (3D), optional
    pivot : (d,) float array
        The point it turns about, at time 0.
    """

    velocity: np.ndarray | None = None
    path: np.ndarray | None = None
    angular_velocity: np.ndarray | float | None = None
    pivot: np.ndarray | None = None

    def translation(self, t: float, dim: int) -> np.ndarray:
        """``u(t)``, the displacement of the pivot at time ``t``."""
        if self.path is not None:
            return np.array([np.interp(t, self.path[:, 0], self.path[:, 1 + c])
                             for c in range(dim)])
        if self.velocity is not None:
            return t * np.asarray(self.velocity, float)
        return np.zeros(dim)

    def place(self, x0: np.ndarray, t: float) -> np.ndarray:
        """The points ``x0`` (rows, at time 0) carried to time ``t``."""
        x0 = np.asarray(x0, dtype=float)
        u = self.translation(t, x0.shape[1])
        if self.angular_velocity is None:
            return x0 + u
        p = np.asarray(self.pivot, float)
        return p + u + (x0 - p) @ rotation(self.angular_velocity, t).T


@dataclass(frozen=True)
class Obstacle:
    """A contact surface: static, or in a prescribed rigid motion.

    Attributes
    ----------
    name : str
        What it is, for messages (``"plane"``, ``"sphere"``, the file's name).
    vertices : (m, d) float array
        Its vertices at time 0.
    faces : (k, 3) triangles (3D) or (k, 2) segments (2D), int array
    velocity : (d,) float array, optional
        A prescribed constant velocity (the vertices at time ``t`` are ``vertices + t
        velocity``), the short form of ``motion=Motion(velocity=...)``; ``None``: static.
    motion : Motion, optional
        A prescribed rigid motion (translation, keyframed path, rotation); with ``velocity``
        given too, ``velocity`` is its translation (a ``path`` then is refused).
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    velocity: np.ndarray | None = None
    motion: Motion | None = None

    def __post_init__(self):
        if self.velocity is not None and self.motion is not None and self.motion.path is not None:
            raise InputError("contact.obstacles: give a velocity or a path, not both")

    @property
    def dim(self) -> int:
        return int(self.vertices.shape[1])

    @property
    def moving(self) -> bool:
        """Whether it moves at all."""
        m = self.motion
        return bool((self.velocity is not None and np.any(self.velocity)) or (
            m is not None and (m.path is not None or m.velocity is not None
                               and np.any(m.velocity) or m.angular_velocity is not None
                               and np.any(m.angular_velocity))))

    def at(self, t: float) -> np.ndarray:
        """Its vertices at time ``t``."""
        m = self.motion or Motion()
        if self.velocity is not None and m.path is None:
            m = replace(m, velocity=np.asarray(self.velocity, float))
        return m.place(self.vertices, t)


def _boundary(cells: np.ndarray, local: np.ndarray) -> np.ndarray:
    """Facets (rows of ``cells[:, local]``) used by exactly one cell, in the cell's orientation."""
    loc = cells[:, local].reshape(-1, local.shape[1])
    key = np.sort(loc, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return loc[counts[inverse.ravel()] == 1]


def body_surface(cells, dim: int) -> np.ndarray:
    """The contact surface of a body from its cells, in its node numbering.

    Parameters
    ----------
    cells : (m, 4) tetrahedra, (m, 3) triangles or (m, 2) segments
    dim : 2 or 3, the space dimension

    Returns
    -------
    (k, 3) boundary triangles of tetrahedra (outward) or the triangles of a 3-D surface (cloth);
    (k, 2) boundary segments of triangles in 2D, or the segments themselves.

    >>> body_surface([[0, 1, 2, 3]], 3).shape
    (4, 3)
    >>> body_surface([[0, 1, 2], [1, 3, 2]], 2).tolist()
    [[0, 1], [2, 0], [1, 3], [3, 2]]
    """
    cells = np.asarray(cells, dtype=np.int64)
    width = cells.shape[1] if cells.ndim == 2 else 0
    if dim == 3 and width == 4:
        return _boundary(cells, np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]]))
    if dim == 3 and width == 3:
        return cells
    if dim == 2 and width == 3:
        return _boundary(cells, np.array([[0, 1], [1, 2], [2, 0]]))
    if dim == 2 and width == 2:
        return cells
    raise InputError(f"contact: no contact surface for cells of {width} nodes in {dim}D "
                     "(tetrahedra or triangles in 3D, triangles or segments in 2D)")


def plane_obstacle(point, normal, half_size: float, dim: int) -> Obstacle:
    """A plane through ``point`` with unit ``normal`` (the side the bodies are on), as a square
    of half-width ``half_size`` centred at ``point`` (a segment in 2D).

    >>> plane_obstacle([0, 0, 0], [0, 0, 1], 2.0, 3).vertices[:, 2].tolist()
    [0.0, 0.0, 0.0, 0.0]
    """
    p = np.asarray(point, dtype=float).reshape(dim)
    n = np.asarray(normal, dtype=float).reshape(dim)
    length = float(np.linalg.norm(n))
    if not length > 0.0:
        raise InputError("contact.obstacles: a plane's normal must be non-zero")
    n = n / length
    if dim == 2:
        t = np.array([n[1], -n[0]])
        return Obstacle("plane", np.array([p - half_size * t, p + half_size * t]),
                        np.array([[0, 1]]))
    a = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    corners = np.array([p + half_size * (s * a + r * b) for s, r in
                        ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    if np.dot(np.cross(corners[1] - corners[0], corners[2] - corners[0]), n) < 0:
        faces = faces[:, ::-1]
    return Obstacle("plane", corners, faces)


def _icosphere(level: int) -> tuple[np.ndarray, np.ndarray]:
    t = (1.0 + 5 ** 0.5) / 2.0
    v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
         [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    verts = [np.array(p, float) / np.linalg.norm(p) for p in v]
    faces = [tuple(x) for x in f]
    for _ in range(level):
        mid: dict = {}

        def middle(i, j):
            key = (min(i, j), max(i, j))
            if key not in mid:
                m = verts[i] + verts[j]
                verts.append(m / np.linalg.norm(m))
                mid[key] = len(verts) - 1
            return mid[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return np.array(verts), np.array(faces, dtype=np.int64)


def sphere_obstacle(centre, radius: float, dim: int, level: int = 3) -> Obstacle:
    """A sphere of ``radius`` around ``centre``: a subdivided icosahedron (``level`` 3: 1,280
    triangles, vertices on the sphere) or, in 2D, a polygon of ``8 * 2**level`` sides.

    >>> sphere_obstacle([0, 0, 0], 1.0, 3, level=1).faces.shape
    (80, 3)
    """
    c = np.asarray(centre, dtype=float).reshape(dim)
    if not radius > 0.0:
        raise InputError(f"contact.obstacles: a sphere's radius must be > 0, got {radius!r}")
    if dim == 2:
        k = 8 * 2 ** level
        a = 2 * np.pi * np.arange(k) / k
        verts = c + radius * np.stack([np.cos(a), np.sin(a)], axis=1)
        return Obstacle("sphere", verts, np.stack([np.arange(k), (np.arange(k) + 1) % k], 1))
    v, f = _icosphere(level)
    return Obstacle("sphere", c + radius * v, f)


def file_obstacle(path, dim: int) -> Obstacle:
    """A static surface read by meshio (``.msh``, ``.stl``, ``.obj``, ...): its triangles (3D)
    or line segments (2D); vertices no facet uses are dropped.

    Raises
    ------
    InputError
        The file cannot be read, or holds no surface (no triangles in 3D, no lines in 2D: a
        volume mesh or a point cloud is not an obstacle surface).
    """
    import meshio

    path = Path(path)
    try:
        m = meshio.read(path)
    except Exception as exc:  # meshio raises many kinds; the message is the reason
        raise InputError(f"contact.obstacles: cannot read {path.name}: "
                         f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
    want = "triangle" if dim == 3 else "line"
    blocks = [np.asarray(c.data, dtype=np.int64) for c in m.cells if c.type == want]
    if not blocks:
        kinds = ", ".join(sorted({c.type for c in m.cells})) or "none"
        raise InputError(f"contact.obstacles: {path.name} is not a surface: it holds no "
                         f"{want}s (cells: {kinds}); an obstacle is a {want} mesh")
    faces = np.concatenate(blocks)
    pts = np.asarray(m.points, dtype=float)[:, :dim]
    used, faces = np.unique(faces, return_inverse=True)
    return Obstacle(path.name, pts[used], faces.reshape(-1, 2 if dim == 2 else 3))
