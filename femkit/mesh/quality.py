"""Size and shape metrics of a triangle or tetrahedral mesh.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> q = quality(Mesh(points=np.array([[0., 0.], [1., 0.], [0., 1.]]), triangles=np.array([[0, 1, 2]])))
>>> round(q["min_angle"], 6), round(q["max_aspect_ratio"], 6)
(45.0, 1.207107)
"""

from __future__ import annotations

import weakref

import numpy as np

from .mesh import Mesh
from ..warmup_registry import register_kernels, register_threshold

#: Triangle meshes made by red refinement from a root mesh of at most this many triangles
#: (:func:`note_red_refinement`) get their numbers from the root's, without a pass of their own.
SIMILAR_ROOT_MAX = 200_000

#: ``mesh -> (root, levels)``: ``mesh`` is ``root`` red-refined ``levels`` times (nodes maybe
#: renumbered). Weakly keyed; the root (small) is kept alive by its descendants' entries.
_SIMILAR: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def note_red_refinement(fine: Mesh, coarse: Mesh) -> None:
    """Record that the triangle mesh ``fine`` is ``coarse`` after one red refinement, so that
    :func:`quality` takes ``fine``'s numbers from its root's (nothing is computed now).

    Red refinement cuts a triangle by its midsegments into four triangles similar to it, of
    half its size (Bank, Sherman and Weiser 1983): the angles, the aspect ratios and the area are
    the parent's, the longest and the shortest edges halve, and the ``E`` edges, ``T``
    triangles and perimeter sum ``P`` become ``2 E + 3 T``, ``4 T`` and ``2 P``, with an
    edge length sum ``S + P / 2``. Equal to the numbers of a pass over the fine mesh to
    round-off (the midpoints are rounded once). Like the cached edges
    (:func:`femkit.mesh.edges.edges`), the note holds while the mesh's arrays are not changed in
    place (a :class:`Mesh` is frozen: a moved mesh is a new Mesh, with no note).
    """
    if coarse.dim != 2:
        return  # Bey's tetrahedra are not all similar to their parent
    try:
        root, levels = _SIMILAR.get(coarse, (coarse, 0))
        if root.n_cells <= SIMILAR_ROOT_MAX:
            _SIMILAR[fine] = (root, levels + 1)
    except TypeError:  # a mesh-like object that cannot be weakly referenced
        pass


def note_renumbered(new: Mesh, old: Mesh) -> None:
    """``new`` is ``old`` with its nodes (and maybe its elements) renumbered: the same numbers."""
    try:
        hit = _SIMILAR.get(old)
        if hit is not None:
            _SIMILAR[new] = hit
    except TypeError:
        pass


def _similar_numbers(mesh: Mesh) -> dict | None:
    """:func:`quality` of a mesh noted by :func:`note_red_refinement`, from its root's; None
    when it was not noted."""
    try:
        hit = _SIMILAR.get(mesh)
    except TypeError:
        return None
    if hit is None:
        return None
    root, levels = hit
    if root.n_cells * 4 ** levels != mesh.n_cells:
        return None
    from .edges import edges

    q = quality(root)
    p = root.points[root.triangles]
    sides = np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2)
    n_edges, n_tri, perim = len(edges(root)[0]), root.n_cells, float(sides.sum())
    total = q["h_mean"] * n_edges
    for _ in range(levels):
        total, n_edges, n_tri, perim = total + perim / 2, 2 * n_edges + 3 * n_tri, 4 * n_tri, 2 * perim
    scale = 0.5 ** levels
    q.update(n_points=mesh.n_points, n_triangles=mesh.n_triangles, h_max=q["h_max"] * scale,
             h_min=q["h_min"] * scale, h_mean=total / max(n_edges, 1))
    return q


def side_lengths_and_angles(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Side lengths and angles (degrees) of triangles given by their corners ``p`` (m, 3, 2).

    Column k of both is the side opposite / the angle at vertex k (law of cosines); degenerate
    triangles give NaN angles.
    """
    e = p[:, [2, 0, 1]] - p[:, [1, 2, 0]]                # edge opposite vertex k
    lens = np.sqrt(np.einsum("ijk,ijk->ij", e, e))       # (m, 3)
    a, b, c = lens, lens[:, [1, 2, 0]], lens[:, [2, 0, 1]]
    with np.errstate(divide="ignore", invalid="ignore"):
        cosang = np.clip((b * b + c * c - a * a) / (2.0 * b * c), -1.0, 1.0)
        return lens, np.degrees(np.arccos(cosang))


def dihedral_angles(p: np.ndarray) -> np.ndarray:
    """Dihedral angles (degrees) of tetrahedra given by their corners ``p`` (m, 4, 3), (m, 6).

    Column order: at edges 23, 13, 12, 03, 02, 01 (the angle between the two faces through an
    edge, from their outward normals: ``pi - angle(n_a, n_b)``).
    """
    from itertools import combinations

    from .faces import LOCAL_FACES

    normals = []
    for f in LOCAL_FACES:
        v = np.cross(p[:, f[1]] - p[:, f[0]], p[:, f[2]] - p[:, f[0]])
        with np.errstate(divide="ignore", invalid="ignore"):
            normals.append(v / np.linalg.norm(v, axis=1)[:, None])
    cos = [np.einsum("md,md->m", normals[a], normals[b]) for a, b in combinations(range(4), 2)]
    return 180.0 - np.degrees(np.arccos(np.clip(np.stack(cos, axis=1), -1.0, 1.0)))


def radius_ratios(p: np.ndarray) -> np.ndarray:
    """``3 r_in / R_circ`` of tetrahedra with corners ``p`` (m, 4, 3): 1 for a regular one, 0
    for a flat one."""
    a, b, c = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    vol6 = np.abs(np.einsum("md,md->m", a, np.cross(b, c)))
    sq = lambda v: np.einsum("md,md->m", v, v)[:, None]  # noqa: E731
    num = np.linalg.norm(sq(a) * np.cross(b, c) + sq(b) * np.cross(c, a) + sq(c) * np.cross(a, b), axis=1)
    from .faces import LOCAL_FACES

    face_area = sum(0.5 * np.linalg.norm(np.cross(p[:, f[1]] - p[:, f[0]], p[:, f[2]] - p[:, f[0]]), axis=1)
                    for f in LOCAL_FACES)
    with np.errstate(divide="ignore", invalid="ignore"):
        r_in = 0.5 * vol6 / face_area          # 3 V / S
        r_circ = num / (2.0 * vol6)            # |...| / (12 V)
        return np.where(vol6 > 0, 3.0 * r_in / r_circ, 0.0)


def _quality_3d(mesh: Mesh) -> dict:
    from .edges import edges

    if mesh.n_cells >= NUMBA_THRESHOLD_3D:
        return _quality_3d_compiled(mesh)
    p = mesh.points[mesh.cells]
    edge_nodes, _ = edges(mesh)
    lens = np.linalg.norm(mesh.points[edge_nodes[:, 1]] - mesh.points[edge_nodes[:, 0]], axis=1)
    ang = dihedral_angles(p)
    rr = radius_ratios(p)
    return _numbers_3d(mesh, lens, float(np.nanmin(ang)), float(np.nanmax(ang)), rr,
                       float(mesh.volumes().sum()))


def _numbers_3d(mesh: Mesh, lens: np.ndarray, d_min: float, d_max: float, rr: np.ndarray,
                volume: float) -> dict:
    return {
        "n_points": mesh.n_points,
        "n_tetrahedra": mesh.n_cells,
        "h_max": float(lens.max()),
        "h_min": float(lens.min()),
        "h_mean": float(lens.mean()),
        "min_dihedral": d_min,
        "max_dihedral": d_max,
        "min_radius_ratio": float(rr.min()),
        "mean_radius_ratio": float(rr.mean()),
        "volume": volume,
    }


def _quality_3d_compiled(mesh: Mesh) -> dict:
    """:func:`_quality_3d` by one compiled pass (:func:`~._quality_kernel.tetrahedron_quality`):
    the same floats, without the (m, 4, 3) corner array and the NumPy temporaries (at 5.3M
    tetrahedra 47 s and several GB become about a second and 16 bytes per tetrahedron)."""
    from itertools import combinations

    from ._quality_kernel import edge_lengths, tetrahedron_quality
    from .edges import edges
    from .faces import LOCAL_FACES

    pairs = np.array(list(combinations(range(4), 2)), dtype=np.int64)
    rr, vol = np.empty(mesh.n_cells), np.empty(mesh.n_cells)
    c_min, c_max = tetrahedron_quality(mesh.points, mesh.cells, LOCAL_FACES.astype(np.int64),
                                       pairs, rr, vol)
    # the extreme angles are the arccos of the extreme cosines (monotone), formed as NumPy does
    d_min, d_max = 180.0 - np.degrees(np.arccos(np.clip(np.array([c_min, c_max]), -1.0, 1.0)))
    volume = float(vol.sum())
    del vol
    lens = edge_lengths(mesh.points, edges(mesh)[0])
    return _numbers_3d(mesh, lens, float(d_min), float(d_max), rr, volume)


def quality(mesh: Mesh) -> dict:
    """Mesh size and shape numbers.

    On a tetrahedral mesh: ``n_points``, ``n_tetrahedra``, ``h_max``/``h_min``/``h_mean`` (over
    unique edges), ``min_dihedral``/``max_dihedral`` (degrees), ``min_radius_ratio`` /
    ``mean_radius_ratio`` (``3 r_in / R_circ``, 1 for a regular tetrahedron) and ``volume``.
    On a triangle mesh:

    Returns
    -------
    dict with
        ``n_points``, ``n_triangles``;
        ``h_max`` (longest edge), ``h_min`` (shortest edge), ``h_mean`` (mean over unique edges);
        ``min_angle``, ``max_angle`` (degrees, over all triangles);
        ``max_aspect_ratio``, ``mean_aspect_ratio``: circumradius / (2 inradius), 1 for an
        equilateral triangle, infinite for a degenerate one;
        ``area`` (total area).

    A triangle mesh red-refined from a small root (:func:`note_red_refinement`: what
    :func:`~femkit.mesh.refine` and a hierarchy note) has its numbers from the root's and the
    similarity of the children, without a pass over its triangles.
    """
    if mesh.dim == 3:
        return _quality_3d(mesh)
    similar = _similar_numbers(mesh)
    if similar is not None:
        return similar
    from .edges import edges

    if mesh.n_cells >= NUMBA_THRESHOLD:
        return _quality_compiled(mesh)
    area = mesh.areas()
    aspect = np.empty(mesh.n_cells)
    h_max, h_min, a_min, a_max = -np.inf, np.inf, np.nan, np.nan
    for lo in range(0, max(mesh.n_cells, 1), _BLOCK):  # block by block: small temporaries
        s = slice(lo, lo + _BLOCK)
        lens, ang = side_lengths_and_angles(mesh.points[mesh.triangles[s]])
        if not lens.size:
            continue
        h_max, h_min = max(h_max, float(lens.max())), min(h_min, float(lens.min()))
        with np.errstate(divide="ignore", invalid="ignore"):
            if not np.isnan(ang).all():
                a_min = np.nanmin([a_min, np.nanmin(ang)])
                a_max = np.nanmax([a_max, np.nanmax(ang)])
            ar = area[s]
            half = 0.5 * lens.sum(axis=1)
            circum = lens.prod(axis=1) / (4.0 * ar)
            inr = ar / half
            aspect[s] = np.where(ar > 0, circum / (2.0 * inr), np.inf)
    edge_nodes, _ = edges(mesh)
    d = mesh.points[edge_nodes[:, 1]] - mesh.points[edge_nodes[:, 0]]
    unique_len = np.hypot(d[:, 0], d[:, 1])
    return {
        "n_points": mesh.n_points,
        "n_triangles": mesh.n_triangles,
        "h_max": h_max,
        "h_min": h_min,
        "h_mean": float(unique_len.mean()),
        "min_angle": float(a_min),
        "max_angle": float(a_max),
        "max_aspect_ratio": float(aspect.max()),
        "mean_aspect_ratio": float(aspect.mean()),
        "area": float(area.sum()),
    }


#: Triangles per block of :func:`quality` (its (block, 3, 2) temporaries stay small).
_BLOCK = 1 << 16

#: Triangle meshes with at least this many cells get their numbers from one compiled pass
#: (:mod:`femkit.mesh._quality_kernel`: no temporaries; the same formulas, equal to round-off).
NUMBA_THRESHOLD = 200_000

#: Tetrahedral meshes with at least this many cells get theirs from one compiled pass
#: (:func:`~._quality_kernel.tetrahedron_quality`: the same floats as the NumPy formulas).
NUMBA_THRESHOLD_3D = 50_000
register_threshold(__name__, "NUMBA_THRESHOLD", "NUMBA_THRESHOLD_3D")
register_kernels("mesh passes", "femkit.mesh._quality_kernel", "triangle_quality", "mean_edge_length", rank=0)
register_kernels("mesh passes", "femkit.mesh._quality_kernel", "edge_lengths", "tetrahedron_quality", rank=0,
                 tetrahedra_only=True)


def _quality_compiled(mesh: Mesh) -> dict:
    from ._quality_kernel import mean_edge_length, triangle_quality
    from .edges import edges

    h_max, h_min, a_min, a_max, asp_max, asp_sum, area = triangle_quality(mesh.points, mesh.triangles)
    edge_nodes, _ = edges(mesh)  # shared with the estimator (cached per mesh)
    return {
        "n_points": mesh.n_points,
        "n_triangles": mesh.n_triangles,
        "h_max": float(h_max),
        "h_min": float(h_min),
        "h_mean": float(mean_edge_length(mesh.points, edge_nodes)),
        "min_angle": float(a_min),
        "max_angle": float(a_max),
        "max_aspect_ratio": float(asp_max),
        "mean_aspect_ratio": float(asp_sum / max(mesh.n_cells, 1)),
        "area": float(area),
    }
