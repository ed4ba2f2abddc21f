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
    kw = dict(points=mesh.points, cells=mesh.cells, cell_tags=mesh.cell_tags,
              boundary_facets=mesh.boundary_facets, boundary_tags=mesh.boundary_tags,
              tag_names=mesh.tag_names)
    kw.update(changes)
    return Mesh(**kw)


def orient_ccw(mesh: Mesh) -> Mesh:
    """Return the mesh with every cell positively oriented: triangles counter-clockwise,
    tetrahedra with ``det[x1 - x0, x2 - x0, x3 - x0] > 0`` (swaps the last two vertices of
    negative ones).

    The input is returned unchanged when it is already oriented.
    """
    cw = mesh.signed_volumes() < 0
    if not cw.any():
        return mesh
    cells = mesh.cells.copy()
    a, b = mesh.dim - 1, mesh.dim
    cells[cw, a], cells[cw, b] = mesh.cells[cw, b], mesh.cells[cw, a]
    return _replace(mesh, cells=cells)


#: The dimension-neutral name of :func:`orient_ccw`.
orient = orient_ccw


def remove_unreferenced(mesh: Mesh) -> Mesh:
    """Drop nodes no cell uses and renumber (order kept); facets on dropped nodes go too."""
    used = np.zeros(mesh.n_points, bool)
    used[mesh.cells.ravel()] = True
    if used.all():
        return mesh
    new = np.full(mesh.n_points, -1, np.int64)
    new[used] = np.arange(int(used.sum()))
    be = new[mesh.boundary_facets] if len(mesh.boundary_facets) else mesh.boundary_facets
    keep = (be >= 0).all(axis=1) if len(be) else np.zeros(0, bool)
    return _replace(mesh, points=mesh.points[used], cells=new[mesh.cells],
                    boundary_facets=be[keep], boundary_tags=mesh.boundary_tags[keep])


def validate(mesh: Mesh, *, rel_area_tol: float = 1e-12, dup_tol: float = 1e-12) -> Mesh:
    """Check a mesh (triangles or tetrahedra); return it positively oriented or raise naming
    the problem.

    Checks, in order: at least one cell; finite coordinates; indices in range (cells and
    boundary facets); cells repeating a vertex; zero/near-zero area or volume cells
    (``area <= rel_area_tol * longest_edge**2``, ``volume <= rel_area_tol *
    longest_edge**3``, scale-free tests); unreferenced nodes; duplicate nodes (closer than
    ``dup_tol`` times the bounding-box diagonal).

    Raises
    ------
    DegenerateMeshError
        Repeated vertices or near-zero area; ``.element_ids`` lists all of them, the message
        the count and up to ten ids.
    MeshError
        Everything else (the message says how many and which).
    """
    n, m = mesh.n_points, mesh.n_cells
    cell, facet, d = mesh.cell_name, f"boundary {mesh.facet_name}", mesh.dim
    if m == 0:
        raise MeshError(f"mesh has no {'triangles' if d == 2 else 'tetrahedra'}")
    if not np.isfinite(mesh.points).all():
        bad = np.flatnonzero(~np.isfinite(mesh.points).all(axis=1))
        raise MeshError(f"{len(bad)} node(s) with non-finite coordinates: node ids {_ids(bad)}")
    tri = mesh.cells
    out = np.flatnonzero(((tri < 0) | (tri >= n)).any(axis=1))
    if len(out):
        raise MeshError(f"{len(out)} {cell}(s) refer to nodes outside 0..{n - 1}: "
                        f"element ids {_ids(out)}")
    be = mesh.boundary_facets
    if len(be):
        eout = np.flatnonzero(((be < 0) | (be >= n)).any(axis=1))
        if len(eout):
            raise MeshError(f"{len(eout)} {facet}(s) refer to nodes outside 0..{n - 1}: "
                            f"{mesh.facet_name} ids {_ids(eout)}")
    srt = np.sort(tri, axis=1)
    rep = np.flatnonzero((srt[:, 1:] == srt[:, :-1]).any(axis=1))
    if len(rep):
        raise DegenerateMeshError(f"{len(rep)} {cell}(s) repeat a vertex: element ids {_ids(rep)}",
                                  element_ids=rep)
    from .mesh import LOCAL_EDGES

    p = mesh.points[tri]
    le = LOCAL_EDGES[d + 1]
    e = p[:, le[:, 1]] - p[:, le[:, 0]]
    lmax2 = np.einsum("ijk,ijk->ij", e, e).max(axis=1)
    size = np.abs(mesh.signed_volumes())
    what = "area" if d == 2 else "volume"
    degen = np.flatnonzero(size <= rel_area_tol * lmax2 ** (d / 2))
    if len(degen):
        raise DegenerateMeshError(
            f"{len(degen)} degenerate {cell}(s) ({what} <= {rel_area_tol:g} x longest edge^{d}): "
            f"element ids {_ids(degen)}", element_ids=degen)
    used = np.zeros(n, bool)
    used[tri.ravel()] = True
    if not used.all():
        un = np.flatnonzero(~used)
        raise MeshError(f"{len(un)} unreferenced node(s) (used by no {cell}): node ids {_ids(un)}; "
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
                            f"{mesh.facet_name if kind == 'boundary' else 'cell'} of the mesh; "
                            f"available {kind} tags: {avail_txt}")
        out.append(num)
    return out
