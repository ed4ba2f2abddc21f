"""Read and write meshes through meshio (``.msh`` v2/v4, ``.vtu``, ``.xdmf``, ...).

meshio is imported inside the functions; its gmsh reader is pure Python, so reading a ``.msh``
file never imports gmsh.

Tags are stored the gmsh way in every format: cell data ``gmsh:physical`` (and
``gmsh:geometrical``) on the ``triangle`` and ``line`` blocks, names in ``field_data``
(``{name: [tag, dim]}``). ``.msh`` 4.1 is written by femkit's own small ASCII writer (one
entity per tag; an edge with several tags is repeated once per tag), ``.msh`` 2.2 and the other
formats by meshio. Formats whose field data do not carry the names (``.vtu``, ``.xdmf``) get a
sidecar ``<file>.tags.json`` (``{name: tag}``), which :func:`read_mesh` reads back.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
from pathlib import Path

import numpy as np

from ..errors import MeshError
from .mesh import Mesh
from .vtk import Later, write_cells

_SIDECAR = ".tags.json"


def _sidecar(path: str) -> str:
    return path + _SIDECAR


def _block_tags(mesh_io, i: int, n: int) -> np.ndarray:
    data = mesh_io.cell_data.get("gmsh:physical")
    if data is None or i >= len(data) or data[i] is None:
        return np.zeros(n, np.int32)
    return np.asarray(data[i]).reshape(-1).astype(np.int32)


def read_mesh(path: str | os.PathLike, *, compact: bool = True, orient: bool = True) -> Mesh:
    """Read a triangle or tetrahedral mesh; physical tags and names become
    ``cell_tags``/``boundary_tags``/``tag_names``.

    A file with ``tetra`` cells is a 3D mesh: its triangles become the tagged boundary faces.

    Parameters
    ----------
    path : mesh file; the format is taken from the extension (``.msh`` v2 or v4, ``.vtu``,
        ``.xdmf`` and anything else meshio reads)
    compact : drop nodes used by no cell (e.g. geometry points such as circle centres that
        gmsh writes) and renumber, keeping the order of the rest
    orient : make every cell positively oriented (:func:`femkit.mesh.validate.orient_ccw`);
        False keeps the file's vertex order (a caller that reports how many it re-orients)

    A ``.vtu`` whose raw appended arrays meshio misreads (femkit's own solution files before
    :func:`femkit.mesh.vtk.reappended`'s layout) is read re-appended.

    Triangles are made counter-clockwise (``orient``); a 3D point array whose z is zero is reduced to 2D.

    Raises
    ------
    MeshError
        Missing file (the path is named), a file meshio cannot read, no (linear) triangles
        (the cell types found are named), mixed triangle/other 2D cells, or non-planar points
        without tetrahedra; for tetrahedra: other 3D cells, triangles that are not faces of
        the tetrahedra (mixed dimensions), tetrahedra outside every physical volume.
    """
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise MeshError(f"mesh file not found: {p}")
    mio = _meshio_read(p)
    types = [c.type for c in mio.cells]
    dim = 3 if "tetra" in types else 2
    cell_type, facet_type = _CELL_TYPE[dim]
    cell_blocks, cell_tags, facet_blocks, facet_tags = [], [], [], []
    for i, block in enumerate(mio.cells):
        data = np.asarray(block.data, dtype=np.int64)
        if block.type == cell_type:
            cell_blocks.append(data)
            cell_tags.append(_block_tags(mio, i, len(data)))
        elif block.type == facet_type:
            tags = _block_tags(mio, i, len(data))
            facet_blocks.append(data)
            facet_tags.append(tags)
            # msh 4.1: an entity in several physical groups -> meshio keeps only the first in
            # gmsh:physical but records every membership in cell_sets; repeat those facets
            for name, (t, gdim) in _groups(mio).items():
                idx = (mio.cell_sets.get(name) or [None] * (i + 1))[i]
                if gdim != dim - 1 or idx is None or len(idx) == 0:
                    continue
                idx = np.asarray(idx, dtype=np.int64)
                extra = idx[tags[idx] != t]
                if len(extra):
                    facet_blocks.append(data[extra])
                    facet_tags.append(np.full(len(extra), t, np.int32))
    pts = np.asarray(mio.points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] not in (2, 3):
        raise MeshError(f"{p}: points have shape {pts.shape}, expected (n, 2) or (n, 3)")
    if not cell_blocks:
        found = ", ".join(sorted(set(types))) or "no cells at all"
        raise MeshError(f"{p} holds no linear triangles (found cell types: {found}); "
                        "femkit needs a P1 triangle mesh")
    allowed = {"triangle", "line", "vertex"} | ({"tetra"} if dim == 3 else set())
    other = sorted(set(types) - allowed)
    if other:
        what = "tetrahedra" if dim == 3 else "triangles"
        raise MeshError(f"{p} mixes {what} with other cells ({', '.join(other)}); "
                        f"femkit needs a pure linear-{'tetrahedron' if dim == 3 else 'triangle'} mesh")
    if dim == 2 and pts.shape[1] == 3:
        z = pts[:, 2]
        scale = max(float(np.abs(pts[:, :2]).max(initial=0.0)), 1.0)
        if np.abs(z).max(initial=0.0) > 1e-12 * scale:
            raise MeshError(f"{p}: points are not in the plane z = 0 "
                            f"(|z| up to {np.abs(z).max():.3g}) and the file holds no tetrahedra: "
                            "a surface, not a volume (gmsh saves only elements of physical groups:"
                            " a volume with no physical group is left out)")
        pts = pts[:, :2]
    if dim == 3 and pts.shape[1] != 3:
        raise MeshError(f"{p}: tetrahedra need 3D points, got shape {pts.shape}")

    names: dict[str, int] = {}
    for name, val in (mio.field_data or {}).items():
        arr = np.asarray(val).ravel()
        if arr.size >= 1 and np.issubdtype(arr.dtype, np.number):
            names[str(name)] = int(arr[0])
    names.update(_read_extra_names(mio, p))

    cells = np.concatenate(cell_blocks)
    ct = np.concatenate(cell_tags)
    be = np.concatenate(facet_blocks) if facet_blocks else np.zeros((0, dim), np.int64)
    bt = np.concatenate(facet_tags) if facet_tags else np.zeros(0, np.int32)
    n = len(pts)
    if cells.min(initial=0) < 0 or cells.max(initial=0) >= n:
        raise MeshError(f"{p}: {'triangles' if dim == 2 else 'tetrahedra'} refer to nodes "
                        f"outside 0..{n - 1}")
    if dim == 3:
        _check_volume_file(p, cells, ct, be, names, _groups(mio))
    from .validate import orient_ccw, remove_unreferenced

    mesh = Mesh(points=pts, cells=cells, cell_tags=ct,
                boundary_facets=be, boundary_tags=bt, tag_names=names)
    if compact:
        mesh = remove_unreferenced(mesh)
    return orient_ccw(mesh) if orient else mesh


def _check_volume_file(p: str, tets, tet_tags, tri, names, groups) -> None:
    """Refuse, in one line, a tetrahedral file whose triangles are not faces of its
    tetrahedra (a 2D domain beside the 3D one: mixed dimensions) or whose physical groups
    leave some tetrahedra out (a volume with no physical group)."""
    from .faces import LOCAL_FACES, unique_rows

    if len(tri):
        faces = np.sort(tets[:, LOCAL_FACES].reshape(-1, 3), axis=1)
        uniq, _ = unique_rows(faces)
        both, inv = unique_rows(np.concatenate([uniq, np.sort(tri, axis=1)]))
        known = np.zeros(len(both), bool)
        known[inv[:len(uniq)]] = True
        loose = int((~known[inv[len(uniq):]]).sum())
        if loose:
            raise MeshError(f"{p} mixes dimensions: {loose} triangle(s) are not faces of its "
                            f"{len(tets)} tetrahedra (a 2D domain beside the volume?); femkit "
                            "needs one volume with its boundary faces")
    # with no physical group at all gmsh writes every element (untagged, as in 2D): accepted;
    # any group but some tetrahedra in no Physical Volume: refused, named
    untagged = int((tet_tags == 0).sum())
    if groups and untagged:
        raise MeshError(f"{p}: {untagged} of {len(tets)} tetrahedra belong to no physical "
                        "volume; add them to a Physical Volume (or remove the other groups)")


def _meshio_read(p: str):
    """meshio's reading of the file ``p``, a ``.vtu`` that meshio misreads (raw appended arrays
    in declared order, as femkit wrote them before :func:`femkit.mesh.vtk.reappended`'s
    layout) read again re-appended; any failure is one :class:`MeshError` line."""
    import meshio

    fmt = "gmsh" if p.lower().endswith(".msh") else None

    def attempt(path: str):
        # meshio prints its own complaints and calls sys.exit() when a reader fails: keep
        # its output off the user's terminal and turn every failure into one MeshError line
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            return meshio.read(path, file_format=fmt)

    try:
        return attempt(p)
    except (Exception, SystemExit):  # ReadError, KeyError, ValueError, UnicodeDecodeError, exit
        pass
    if p.lower().endswith(".vtu"):
        import tempfile

        from .vtk import reappended

        with open(p, "rb") as fh:
            fixed = reappended(fh.read())
        if fixed is not None:
            with tempfile.TemporaryDirectory(prefix="femkit-vtu-") as tmp:
                again = os.path.join(tmp, "reappended.vtu")
                with open(again, "wb") as fh:
                    fh.write(fixed)
                with contextlib.suppress(Exception, SystemExit):
                    return attempt(again)
    raise MeshError(unreadable_message(p))


#: What each extension must hold, for the messages of unreadable files.
_EXPECTED = {
    ".msh": "a gmsh mesh (.msh, ASCII or binary, format 2.2 or 4.1)",
    ".vtu": "a VTK XML unstructured grid (.vtu)",
    ".xdmf": "an XDMF mesh (.xdmf with its .h5)",
    ".vtk": "a legacy VTK file (.vtk)",
}


def _msh_cause(head: bytes, tail: bytes) -> str:
    """The likely reason a .msh file failed to parse, from its first and last bytes."""
    first = head.lstrip().split(b"\n", 1)[0].strip()
    if first != b"$MeshFormat":
        if b"\0" in head or not head.isascii():
            return "it holds binary data that does not start with $MeshFormat; not a gmsh file?"
        return f"it starts with {first[:40].decode('ascii', 'replace')!r}, not $MeshFormat; not a gmsh file?"
    last = tail.rstrip().rsplit(b"\n", 1)[-1].strip()
    if not last.startswith(b"$End"):
        return "its last section is not closed by an $End... line: truncated?"
    return "a section holds fewer or malformed entries than its header announces: truncated or edited by hand?"


def unreadable_message(path: str) -> str:
    """One line for a mesh file that meshio cannot parse: the file, what was expected, the
    likely cause (empty, truncated, not this format), without internal exception names.

    >>> import tempfile, os
    >>> d = tempfile.mkdtemp(); p = os.path.join(d, "empty.msh"); open(p, "w").close()
    >>> unreadable_message(p).split(": ", 1)[1]
    'not a valid gmsh mesh (.msh, ASCII or binary, format 2.2 or 4.1): the file is empty'
    """
    ext = Path(path).suffix.lower()
    expected = _EXPECTED.get(ext, f"a mesh file meshio reads as {ext or 'its extension'}")
    size = os.path.getsize(path)
    if size == 0:
        cause = "the file is empty"
    else:
        with open(path, "rb") as fh:
            head = fh.read(4096)
            fh.seek(max(size - 4096, 0))
            tail = fh.read()
        if ext == ".msh":
            cause = _msh_cause(head, tail)
        elif ext in (".vtu", ".xdmf"):
            closed = tail.rstrip().endswith(b">")
            cause = ("not well-formed XML" + ("" if closed else ": it ends mid-element, truncated?")
                     if head.lstrip().startswith(b"<") else "it is not XML")
        else:
            cause = "it could not be parsed (truncated, or another format?)"
    return f"{path}: not a valid {expected.replace('a ', '', 1).replace('an ', '', 1)}: {cause}"


def _groups(mio) -> dict[str, tuple[int, int]]:
    """Physical groups from meshio's field_data: ``{name: (tag, dim)}`` (only well-formed ones)."""
    out = {}
    for name, val in (mio.field_data or {}).items():
        arr = np.asarray(val).ravel()
        if arr.size == 2 and np.issubdtype(arr.dtype, np.number):
            out[str(name)] = (int(arr[0]), int(arr[1]))
    return out


def _read_extra_names(mio, path: str) -> dict[str, int]:
    if mio.field_data or not os.path.isfile(_sidecar(path)):
        return {}
    text = Path(_sidecar(path)).read_text()
    try:
        return {str(k): int(v) for k, v in json.loads(text).items()}
    except (ValueError, AttributeError, TypeError) as exc:
        raise MeshError(f"{path}: unreadable tag names ({exc})") from None


def _tag_dims(mesh: Mesh) -> dict[str, int]:
    cells = set(np.unique(mesh.cell_tags).tolist())
    d = mesh.dim
    return {name: (d if int(t) in cells else d - 1) for name, t in mesh.tag_names.items()}


#: meshio cell type of the cells and of the boundary facets, per dimension
_CELL_TYPE = {2: ("triangle", "line"), 3: ("tetra", "triangle")}
#: gmsh element type numbers of the cells and of the facets, per dimension
_GMSH_TYPE = {2: (2, 1), 3: (4, 2)}


def _points3(mesh: Mesh) -> np.ndarray:
    return mesh.points if mesh.dim == 3 else np.column_stack([mesh.points, np.zeros(mesh.n_points)])


def write_mesh(path: str | os.PathLike, mesh: Mesh, point_data: dict | None = None,
               cell_data: dict | None = None, *, msh_version: str = "4.1",
               binary: bool = False, compression: str | None = None) -> None:
    """Write a mesh (and optional data) in the format given by the extension.

    Parameters
    ----------
    path : ``.msh`` (gmsh, ``msh_version`` ``"4.1"`` (ASCII) or ``"2.2"`` (ASCII unless
        ``binary``; mesh and tags only, no data)),
        ``.vtu``, ``.xdmf`` or any other meshio format
    point_data : ``{name: (n,) or (n, k) array}``
    cell_data : ``{name: (m,) or (m, k) array}`` on the cells (tagged boundary facets get
        zeros in the written file), or a :class:`~femkit.mesh.vtk.Later` whose values come
        while the file is written
    compression : ``.vtu`` only: ``none``, ``zlib`` or ``lzma``
        (:data:`femkit.mesh.vtk.COMPRESSIONS`; default :data:`~femkit.mesh.vtk.DEFAULT_COMPRESSION`)

    Physical tags go to ``gmsh:physical`` / ``gmsh:geometrical`` on the ``triangle`` and
    ``line`` blocks (``tetra`` and ``triangle`` for a tetrahedral mesh) and names to
    ``field_data`` (see the module notes), so :func:`read_mesh` gives back the same points,
    cells and tags.
    """
    p = os.fspath(path)
    ext = Path(p).suffix.lower()
    m, k = mesh.n_cells, len(mesh.boundary_facets)
    cell_type, facet_type = _CELL_TYPE[mesh.dim]
    cells = [(cell_type, mesh.cells)]
    with_lines = k > 0
    if with_lines:
        cells.append((facet_type, mesh.boundary_facets))

    def per_block(tri_vals, line_vals):
        return [tri_vals, line_vals] if with_lines else [tri_vals]

    cell_tags = mesh.cell_tags.astype(np.int32, copy=False)  # written, never modified: no copies
    facet_tags = mesh.boundary_tags.astype(np.int32, copy=False)
    cdata = {"gmsh:physical": per_block(cell_tags, facet_tags),
             "gmsh:geometrical": per_block(cell_tags, facet_tags)}
    for name, arr in (cell_data or {}).items():
        a = arr if isinstance(arr, Later) else np.asarray(arr)  # Later: values still to come
        if a.shape[0] != m:
            raise MeshError(f"cell_data {name!r} has {a.shape[0]} rows, mesh has {m} "
                            f"{'triangles' if mesh.dim == 2 else 'tetrahedra'}")
        cdata[name] = per_block(a, np.zeros((k,) + a.shape[1:], a.dtype))
    pdata = {}
    for name, arr in (point_data or {}).items():
        a = np.asarray(arr)
        if a.shape[0] != mesh.n_points:
            raise MeshError(f"point_data {name!r} has {a.shape[0]} rows, mesh has {mesh.n_points} points")
        pdata[name] = a
    Path(p).parent.mkdir(parents=True, exist_ok=True)
    try:
        if ext == ".msh" and msh_version == "4.1" and not binary:
            _write_msh41(p, mesh, pdata, {k: v[0] for k, v in cdata.items()
                                          if not k.startswith("gmsh:")})
            return
        if ext == ".msh" and msh_version not in ("4.1", "2.2"):
            raise MeshError(f"msh_version must be '4.1' or '2.2', got {msh_version!r}")
        dims = _tag_dims(mesh)
        fdata = {name: np.array([int(t), dims[name]]) for name, t in mesh.tag_names.items()}
        if ext == ".msh":
            if msh_version == "4.1":
                raise MeshError("binary msh 4.1 is not supported; use binary=False or msh_version='2.2'")
            if pdata or cell_data:
                raise MeshError("point/cell data are written to msh 4.1 (the default), .vtu or "
                                ".xdmf, not to msh 2.2")
            write_cells(p, mesh.points, cells, cell_data=cdata, field_data=fdata,
                        file_format="gmsh22", binary=binary)
        else:
            write_cells(p, mesh.points, cells, point_data=pdata, cell_data=cdata, field_data=fdata,
                        **({} if compression is None else {"compression": compression}))
            if mesh.tag_names:
                Path(_sidecar(p)).write_text(json.dumps(mesh.tag_names, sort_keys=True))
    except MeshError:
        raise
    except Exception as exc:
        raise MeshError(f"cannot write mesh file {p}: {type(exc).__name__}: {exc}") from None


def _fmt_rows(arr: np.ndarray, fmt: str) -> str:
    if arr.size == 0:
        return ""
    return "\n".join(" ".join(fmt % v for v in row) for row in arr.tolist()) + "\n"


def _write_msh41(path: str, mesh: Mesh, point_data: dict, cell_data: dict) -> None:
    """ASCII gmsh 4.1 writer: one surface entity per cell tag, one curve entity per edge tag
    (in 3D: one volume entity per cell tag, one surface entity per face tag).

    A facet carrying several tags is written once per tag (in each tag's entity), so gmsh and
    meshio read the same repeated facets back. Nodes are tagged 1..n in mesh order, cells
    1..m in mesh order, then the facets.
    """
    pts3 = _points3(mesh)
    d = mesh.dim
    cell_code, facet_code = _GMSH_TYPE[d]
    dims = _tag_dims(mesh)
    cell_vals = np.unique(mesh.cell_tags)
    edge_vals = np.unique(mesh.boundary_tags)
    lo, hi = pts3.min(axis=0), pts3.max(axis=0)
    box = " ".join(repr(float(v)) for v in (*lo, *hi))
    out = ["$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"]
    if mesh.tag_names:
        out.append(f"$PhysicalNames\n{len(mesh.tag_names)}\n")
        for name, t in sorted(mesh.tag_names.items(), key=lambda kv: (dims[kv[0]], kv[1])):
            out.append(f'{dims[name]} {int(t)} "{name}"\n')
        out.append("$EndPhysicalNames\n")
    counts = [0, 0, 0, 0]
    counts[d - 1], counts[d] = len(edge_vals), len(cell_vals)
    out.append(f"$Entities\n{' '.join(map(str, counts))}\n")
    for i, t in enumerate(edge_vals, start=1):
        phys = f"1 {int(t)}" if t != 0 else "0"
        out.append(f"{i} {box} {phys} 0\n")
    for i, t in enumerate(cell_vals, start=1):
        phys = f"1 {int(t)}" if t != 0 else "0"
        out.append(f"{i} {box} {phys} 0\n")
    out.append("$EndEntities\n")
    n = mesh.n_points
    out.append(f"$Nodes\n1 {n} 1 {n}\n{d} 1 0 {n}\n")
    out.append("\n".join(map(str, range(1, n + 1))) + "\n")
    out.append(_fmt_rows(pts3, "%.17g"))
    out.append("$EndNodes\n")
    m, k = mesh.n_cells, len(mesh.boundary_facets)
    out.append(f"$Elements\n{len(cell_vals) + len(edge_vals)} {m + k} 1 {m + k}\n")
    ids = np.arange(1, m + 1)
    for i, t in enumerate(cell_vals, start=1):
        sel = np.flatnonzero(mesh.cell_tags == t)
        out.append(f"{d} {i} {cell_code} {len(sel)}\n")
        out.append(_fmt_rows(np.column_stack([ids[sel], mesh.cells[sel] + 1]), "%d"))
    eids = np.arange(m + 1, m + k + 1)
    for i, t in enumerate(edge_vals, start=1):
        sel = np.flatnonzero(mesh.boundary_tags == t)
        out.append(f"{d - 1} {i} {facet_code} {len(sel)}\n")
        out.append(_fmt_rows(np.column_stack([eids[sel], mesh.boundary_facets[sel] + 1]), "%d"))
    out.append("$EndElements\n")
    out.append(_data_sections(mesh, point_data, cell_data))
    Path(path).write_text("".join(out))


def _data_sections(mesh: Mesh, point_data: dict, cell_data: dict) -> str:
    """ASCII ``$NodeData`` / ``$ElementData`` blocks (elements numbered cells first, then facets)."""
    n, m, k = mesh.n_points, mesh.n_cells, len(mesh.boundary_facets)
    out = []
    for name, a in point_data.items():
        a2 = np.asarray(a, dtype=np.float64).reshape(n, -1)
        out.append(f'$NodeData\n1\n"{name}"\n1\n0.0\n3\n0\n{a2.shape[1]}\n{n}\n')
        out.append(_fmt_rows(np.column_stack([np.arange(1, n + 1), a2]), "%.17g"))
        out.append("$EndNodeData\n")
    for name, a in cell_data.items():
        a2 = np.asarray(a, dtype=np.float64).reshape(m, -1)
        a2 = np.vstack([a2, np.zeros((k, a2.shape[1]))])  # edges get zeros (meshio wants all)
        out.append(f'$ElementData\n1\n"{name}"\n1\n0.0\n3\n0\n{a2.shape[1]}\n{m + k}\n')
        out.append(_fmt_rows(np.column_stack([np.arange(1, m + k + 1), a2]), "%.17g"))
        out.append("$EndElementData\n")
    return "".join(out)
