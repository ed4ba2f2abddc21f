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
from .faces import LOCAL_FACES, unique_rows
from .mesh import LOCAL_EDGES, Mesh

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


def unreferenced(mesh: Mesh) -> np.ndarray:
    """Ids of the nodes no cell uses (ascending)."""
    used = np.zeros(mesh.n_points, bool)
    used[mesh.cells.ravel()] = True
    return np.flatnonzero(~used)


def drop_unreferenced(mesh: Mesh) -> tuple[Mesh, str | None]:
    """:func:`remove_unreferenced` and a note saying what it dropped (None when nothing), for
    the caller to print: a mesh file's unused nodes (e.g. the circle centres gmsh writes) are
    dropped, never silently.

    >>> from femkit.mesh import Mesh
    >>> m = Mesh(points=np.array([[0., 0.], [9., 9.], [1., 0.], [0., 1.]]),
    ...          triangles=np.array([[0, 2, 3]]))
    >>> kept, note = drop_unreferenced(m)
    >>> kept.n_points, note
    (3, '1 node used by no triangle dropped (node ids 1)')
    """
    un = unreferenced(mesh)
    if not len(un):
        return mesh, None
    nodes = "node" if len(un) == 1 else "nodes"
    return remove_unreferenced(mesh), (f"{len(un)} {nodes} used by no {mesh.cell_name} dropped "
                                       f"(node ids {_ids(un)})")


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


def validate(mesh: Mesh, *, rel_area_tol: float = 1e-12, dup_tol: float = 1e-12,
             overlap_tol: float = 1e-9) -> Mesh:
    """Check a mesh (triangles or tetrahedra); return it positively oriented or raise naming
    the problem.

    Checks, in order: at least one cell; finite coordinates; indices in range (cells and
    boundary facets); cells repeating a vertex; zero/near-zero area or volume cells
    (``area <= rel_area_tol * longest_edge**2``, ``volume <= rel_area_tol *
    longest_edge**3``, scale-free tests); unreferenced nodes; duplicate nodes (closer than
    ``dup_tol`` times the bounding-box diagonal); overlapping cells (:func:`check_overlaps`:
    two cells on one node set, or a total area off the boundary's enclosed area by more than
    ``overlap_tol`` relative).

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
    un = unreferenced(mesh)
    if len(un):
        raise MeshError(f"{len(un)} unreferenced node(s) (used by no {cell}): node ids {_ids(un)}; "
                        "femkit.mesh.validate.remove_unreferenced(mesh) drops them")
    dup = _duplicate_pairs(mesh.points, dup_tol)
    if len(dup):
        pairs = ", ".join(f"{a}={b}" for a, b in dup[:_SHOW])
        raise MeshError(f"{len(dup)} pair(s) of coincident nodes: {pairs}"
                        + (" ..." if len(dup) > _SHOW else ""))
    mesh = orient_ccw(mesh)
    check_overlaps(mesh, rel_tol=overlap_tol)
    return mesh


def check_overlaps(mesh: Mesh, *, rel_tol: float = 1e-9) -> None:
    """Refuse overlapping cells of a positively oriented mesh, naming them.

    Two checks (Shewchuk's conformity conditions for a simplicial mesh, in their cheap form):

    * no two cells have the same node set (a triangle listed twice);
    * the cells' total area (volume) equals the area (volume) enclosed by the mesh's boundary,
      the facets used by exactly one cell, computed from them alone by the divergence theorem
      (the shoelace formula ``1/2 sum (x_i y_j - x_j y_i)`` over boundary edges; ``1/6 sum
      p0 . (p1 x p2)`` over boundary faces). Cells covering a region twice add to the total but
      not to the enclosed measure.

    The cells named are those on a facet used by more than two cells or twice in the same
    direction (an overlap's seam).

    Raises
    ------
    MeshError
        With the element ids.
    """
    cells, d, cell = mesh.cells, mesh.dim, mesh.cell_name
    local = LOCAL_EDGES[3] if d == 2 else LOCAL_FACES  # outward-oriented facets of each cell
    facets = cells[:, local].reshape(-1, d)
    inverse = _row_ids(np.sort(facets, axis=1), mesh.n_points)
    counts = np.bincount(inverse)
    # orientation of each facet against its sorted form: +1 / -1 (parity of the permutation)
    if d == 2:
        sign = np.where(facets[:, 0] < facets[:, 1], 1.0, -1.0)
    else:
        a, b, c = facets.T
        sign = 1.0 - 2.0 * (((a > b).astype(np.int8) + (a > c) + (b > c)) % 2)
    net = np.bincount(inverse, weights=sign)
    bad_facet = (counts > 2) | ((counts == 2) & (net != 0))
    total = float(np.abs(mesh.signed_volumes()).sum())
    enclosed = _enclosed(mesh.points, facets[counts[inverse] == 1])
    if not bad_facet.any() and abs(total - enclosed) <= rel_tol * total:
        return
    # a cell listed twice (every facet of it is a seam): say so first
    same_set = _row_ids(np.sort(cells, axis=1), mesh.n_points)
    twice = np.bincount(same_set)[same_set] > 1
    if twice.any():
        groups: dict = {}
        for e in np.flatnonzero(twice)[:_SHOW * 4]:
            groups.setdefault(int(same_set[e]), []).append(str(e))
        listed = "; ".join(" = ".join(g) for g in list(groups.values())[:_SHOW])
        raise MeshError(f"{int(twice.sum())} {cell}(s) share their node set with another (an "
                        f"element listed twice): element ids {listed}")
    what, cells_name = ("area", "triangles") if d == 2 else ("volume", "tetrahedra")
    on_seam = np.unique(np.flatnonzero(bad_facet[inverse]) // local.shape[0])
    where = f"element ids {_ids(on_seam)}" if len(on_seam) else "elements not located"
    raise MeshError(f"overlapping {cells_name}: their total {what} {total:.6g} differs from the "
                    f"{what} {enclosed:.6g} enclosed by the mesh boundary; {where}")


def _row_ids(rows: np.ndarray, n: int) -> np.ndarray:
    """A number per distinct row of a sorted-row int array (equal rows, equal numbers): rows
    packed into one int64 when ``n ** width`` fits, else a lexicographic sort."""
    rows = np.asarray(rows, dtype=np.int64)
    if float(n) ** rows.shape[1] < 2.0 ** 62:
        key = rows[:, 0]
        for k in range(1, rows.shape[1]):
            key = key * n + rows[:, k]
        return np.unique(key, return_inverse=True)[1].ravel()
    return unique_rows(rows)[1]


def _enclosed(points: np.ndarray, facets: np.ndarray) -> float:
    """Area (volume) enclosed by outward-oriented boundary edges (faces): divergence theorem."""
    x = points - points.mean(axis=0)  # smaller products, less cancellation
    if facets.shape[1] == 2:
        a, b = x[facets[:, 0]], x[facets[:, 1]]
        return 0.5 * float(np.sum(a[:, 0] * b[:, 1] - b[:, 0] * a[:, 1]))
    a, b, c = (x[facets[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->", a, np.cross(b, c))) / 6.0


def _duplicate_pairs(points: np.ndarray, rel_tol: float) -> np.ndarray:
    """The pairs ``(i, j)``, ``i < j``, of points at most ``rel_tol`` x the bounding-box
    diagonal apart, sorted: ``cKDTree.query_pairs``'s pairs, found by sorting instead of a tree
    (importing ``scipy.spatial`` costs ~0.13 s of every run, more than this check on any mesh).

    Two points at most ``r`` apart share a cell of side ``2 r`` in at least one of the ``2^d``
    grids shifted by ``0`` or ``r`` along each axis (along one axis, ``|a - b| <= r`` cannot
    straddle both a boundary and the boundary shifted by ``r``). Points sharing a cell are the
    candidates; their distance decides.
    """
    points = np.asarray(points, dtype=np.float64)
    n, d = points.shape if points.ndim == 2 else (len(points), 1)
    if n < 2:
        return np.empty((0, 2), dtype=np.intp)
    lo = points.min(axis=0)
    span = float(np.linalg.norm(points.max(axis=0) - lo))
    r = rel_tol * (span if span > 0 else 1.0)
    x = (points - lo) / (2.0 * r)  # in cells of side 2 r
    found = []
    for k in range(2 ** d):
        shift = np.array([0.5 * ((k >> a) & 1) for a in range(d)])  # 0 or r, in cells
        cells = np.floor(x + shift)
        order = np.lexsort(cells.T[::-1])
        c = cells[order]
        same = (c[1:] == c[:-1]).all(axis=1)  # sorted neighbours in one cell
        if not same.any():
            continue
        # every pair inside a run of equal cells: i with i + g for g = 1, 2, ... while in the run
        run = np.flatnonzero(same)
        gap = 1
        while len(run):
            i, j = order[run], order[run + gap]
            near = ((points[i] - points[j]) ** 2).sum(axis=1) <= r * r
            found.append(np.column_stack([np.minimum(i, j), np.maximum(i, j)])[near])
            gap += 1
            nxt = run + gap - 1  # the pair (run, run + gap) is in the run when (run + gap - 1) is
            run = run[nxt < len(same)]
            run = run[same[run + gap - 1]]
    if not found:
        return np.empty((0, 2), dtype=np.intp)
    pairs = np.unique(np.concatenate(found).astype(np.intp), axis=0)  # rows sorted
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
