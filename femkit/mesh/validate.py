"""Mesh checks with errors that say what is wrong and where.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(points=np.array([[0., 0.], [1., 0.], [2., 0.]]), triangles=np.array([[0, 1, 2]]))
>>> validate(m)
Traceback (most recent call last):
...
femkit.errors.DegenerateMeshError: 1 degenerate triangle(s) (area <= 1e-12 x longest edge^2): element ids 0
"""

from __future__ import annotations

from typing import Iterable

import numpy as np

from ..errors import DegenerateMeshError, MeshError
from .mesh import Mesh

_SHOW = 10  # how many ids an error message lists


def _ids(ids: np.ndarray) -> str:
    ids = np.asarray(ids).ravel()
    shown = ", ".join(str(int(i)) for i in ids[:_SHOW])
    return shown + (f", ... ({len(ids)} in all)" if len(ids) > _SHOW else "")


def _replace(mesh: Mesh, **changes) -> Mesh:
    kw = dict(points=mesh.points, triangles=mesh.triangles, cell_tags=mesh.cell_tags,
              boundary_edges=mesh.boundary_edges, boundary_tags=mesh.boundary_tags,
              tag_names=mesh.tag_names)
    kw.update(changes)
    return Mesh(**kw)


def orient_ccw(mesh: Mesh) -> Mesh:
    """Return the mesh with every triangle counter-clockwise (swaps two vertices of CW ones).

    The input is returned unchanged when it is already counter-clockwise.
    """
    cw = mesh.signed_areas() < 0
    if not cw.any():
        return mesh
    tri = mesh.triangles.copy()
    tri[cw, 1], tri[cw, 2] = mesh.triangles[cw, 2], mesh.triangles[cw, 1]
    return _replace(mesh, triangles=tri)


def remove_unreferenced(mesh: Mesh) -> Mesh:
    """Drop nodes no triangle uses and renumber (order kept); edges on dropped nodes go too."""
    used = np.zeros(mesh.n_points, bool)
    used[mesh.triangles.ravel()] = True
    if used.all():
        return mesh
    new = np.full(mesh.n_points, -1, np.int64)
    new[used] = np.arange(int(used.sum()))
    be = new[mesh.boundary_edges] if len(mesh.boundary_edges) else mesh.boundary_edges
    keep = (be >= 0).all(axis=1) if len(be) else np.zeros(0, bool)
    return _replace(mesh, points=mesh.points[used], triangles=new[mesh.triangles],
                    boundary_edges=be[keep], boundary_tags=mesh.boundary_tags[keep])


def validate(mesh: Mesh, *, rel_area_tol: float = 1e-12, dup_tol: float = 1e-12) -> Mesh:
    """Check a mesh; return it counter-clockwise or raise naming the problem.

    Checks, in order: at least one triangle; finite coordinates; indices in range (triangles
    and boundary edges); triangles repeating a vertex; zero/near-zero area triangles
    (``area <= rel_area_tol * longest_edge**2``, a scale-free test); unreferenced nodes;
    duplicate nodes (closer than ``dup_tol`` times the bounding-box diagonal).

    Raises
    ------
    DegenerateMeshError
        Repeated vertices or near-zero area; ``.element_ids`` lists all of them, the message
        the count and up to ten ids.
    MeshError
        Everything else (the message says how many and which).
    """
    n, m = mesh.n_points, mesh.n_triangles
    if m == 0:
        raise MeshError("mesh has no triangles")
    if not np.isfinite(mesh.points).all():
        bad = np.flatnonzero(~np.isfinite(mesh.points).all(axis=1))
        raise MeshError(f"{len(bad)} node(s) with non-finite coordinates: node ids {_ids(bad)}")
    tri = mesh.triangles
    out = np.flatnonzero(((tri < 0) | (tri >= n)).any(axis=1))
    if len(out):
        raise MeshError(f"{len(out)} triangle(s) refer to nodes outside 0..{n - 1}: "
                        f"element ids {_ids(out)}")
    be = mesh.boundary_edges
    if len(be):
        eout = np.flatnonzero(((be < 0) | (be >= n)).any(axis=1))
        if len(eout):
            raise MeshError(f"{len(eout)} boundary edge(s) refer to nodes outside 0..{n - 1}: "
                            f"edge ids {_ids(eout)}")
    rep = np.flatnonzero((tri[:, 0] == tri[:, 1]) | (tri[:, 1] == tri[:, 2]) | (tri[:, 0] == tri[:, 2]))
    if len(rep):
        raise DegenerateMeshError(f"{len(rep)} triangle(s) repeat a vertex: element ids {_ids(rep)}",
                                  element_ids=rep)
    p = mesh.points[tri]
    e = p[:, [1, 2, 0]] - p[:, [2, 0, 1]]
    lmax2 = np.einsum("ijk,ijk->ij", e, e).max(axis=1)
    area = np.abs(mesh.signed_areas())
    degen = np.flatnonzero(area <= rel_area_tol * lmax2)
    if len(degen):
        raise DegenerateMeshError(
            f"{len(degen)} degenerate triangle(s) (area <= {rel_area_tol:g} x longest edge^2): "
            f"element ids {_ids(degen)}", element_ids=degen)
    used = np.zeros(n, bool)
    used[tri.ravel()] = True
    if not used.all():
        un = np.flatnonzero(~used)
        raise MeshError(f"{len(un)} unreferenced node(s) (used by no triangle): node ids {_ids(un)}; "
                        "femkit.mesh.validate.remove_unreferenced(mesh) drops them")
    dup = _duplicate_pairs(mesh.points, dup_tol)
    if len(dup):
        pairs = ", ".join(f"{a}={b}" for a, b in dup[:_SHOW])
        raise MeshError(f"{len(dup)} pair(s) of coincident nodes: {pairs}"
                        + (" ..." if len(dup) > _SHOW else ""))
    return orient_ccw(mesh)


def _duplicate_pairs(points: np.ndarray, rel_tol: float) -> np.ndarray:
    from scipy.spatial import cKDTree

    span = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) if len(points) else 0.0
    r = rel_tol * (span if span > 0 else 1.0)
    pairs = cKDTree(points).query_pairs(r, output_type="ndarray")
    if len(pairs):
        pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
    return pairs


def check_tags(mesh: Mesh, tags: Iterable | str | int, *, kind: str = "boundary") -> list[int]:
    """Resolve tag names/numbers that a case refers to and check the mesh carries them.

    Parameters
    ----------
    tags : a name, a number or an iterable of them
    kind : ``"boundary"`` (must occur in ``boundary_tags``) or ``"cell"`` (in ``cell_tags``)

    Returns
    -------
    the tag numbers, in the order given

    Raises
    ------
    MeshError
        A tag is unknown or carries no edge/cell; the message lists the available ones.
    """
    if kind not in ("boundary", "cell"):
        raise ValueError(f"kind must be 'boundary' or 'cell', got {kind!r}")
    present = np.unique(mesh.boundary_tags if kind == "boundary" else mesh.cell_tags)
    present_set = {int(t) for t in present}
    by_number = {}
    for name, num in mesh.tag_names.items():
        by_number.setdefault(int(num), []).append(name)
    avail = sorted(n for t in present_set for n in by_number.get(t, []))
    avail += [str(t) for t in sorted(present_set) if t not in by_number and t != 0]
    avail_txt = ", ".join(avail) or "(none)"
    if isinstance(tags, (str, int, np.integer)):
        tags = [tags]
    out = []
    for t in tags:
        if isinstance(t, (int, np.integer)) and not isinstance(t, bool):
            num = int(t)
        elif isinstance(t, str) and t in mesh.tag_names:
            num = int(mesh.tag_names[t])
        else:
            raise MeshError(f"mesh has no {kind} tag {t!r}; available {kind} tags: {avail_txt}")
        if num not in present_set:
            raise MeshError(f"{kind} tag {t!r} (number {num}) is carried by no "
                            f"{'edge' if kind == 'boundary' else 'cell'} of the mesh; "
                            f"available {kind} tags: {avail_txt}")
        out.append(num)
    return out
