"""femkit's one VTK writer: points, cell blocks and data to ``.vtu`` (or any meshio format),
and the two XML index files ParaView opens over several ``.vtu`` files.

* :func:`write_cells` is the one call of meshio's writer: a Poisson solution
  (:func:`femkit.mesh.write_mesh`), a scene's frames (springs as ``line`` cells, cloth
  triangles) and each rank's piece of a distributed solution all go through it;
* :func:`write_collection` writes a ``.pvd`` time series (``<Collection>`` of ``.vtu`` files
  with their times);
* :func:`write_parallel_index` writes a ``.pvtu`` index of per-rank pieces, its array
  declarations read back from the first piece so the index always matches what was written.

Both index formats are VTK's XML file formats ("VTK File Formats", Kitware, VTK User's Guide,
section "Parallel XML files" and "Collection files"). meshio and the XML modules (whose
``xml.sax`` pulls in ``urllib`` and ``ssl``) are imported inside the functions, so importing
:mod:`femkit.mesh` stays cheap.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import MeshError

__all__ = ["write_cells", "write_collection", "write_parallel_index", "pad3", "COMPRESSIONS",
           "DEFAULT_COMPRESSION"]

#: Compression of the binary arrays of a ``.vtu`` file (VTK's ``compressor`` attribute):
#: ``none`` writes at disk speed (about 2x the bytes of ``zlib``), ``zlib`` is VTK's usual
#: choice (on a 0.5M-node solution it costs more than the solve), ``lzma`` is smallest and
#: slowest. ParaView reads all three.
COMPRESSIONS = {"none": None, "zlib": "zlib", "lzma": "lzma"}

#: The default: output at disk speed, not on the critical path of a run.
DEFAULT_COMPRESSION = "none"


def pad3(points: np.ndarray) -> np.ndarray:
    """``(n, d)`` coordinates as ``(n, 3)`` float64 (zeros appended), as VTK stores them."""
    a = np.asarray(points, dtype=np.float64)
    if a.shape[1] == 3:
        return a
    return np.concatenate([a, np.zeros((a.shape[0], 3 - a.shape[1]))], axis=1)


def write_cells(path: str | os.PathLike, points: np.ndarray, cells: Sequence[tuple[str, np.ndarray]],
                *, point_data: dict | None = None, cell_data: dict | None = None,
                field_data: dict | None = None, file_format: str | None = None,
                binary: bool | None = None, compression: str = DEFAULT_COMPRESSION) -> Path:
    """Write ``points`` and the cell blocks ``cells`` (``[(meshio type, (k, nv) ints), ...]``)
    with their data, in the format of the extension (or ``file_format``).

    ``point_data``: ``{name: (n,) or (n, c)}``; ``cell_data``: ``{name: [one array per block]}``;
    points are padded to 3D. Parent directories are created. ``compression`` (one of
    :data:`COMPRESSIONS`) applies to ``.vtu`` files.

    Raises
    ------
    MeshError
        A data array whose row count does not match, or meshio cannot write the file.
    """
    p = os.fspath(path)
    if compression not in COMPRESSIONS:
        raise MeshError(f"unknown VTU compression {compression!r}; valid: {', '.join(COMPRESSIONS)}")
    pts = pad3(points)
    blocks = [(kind, np.asarray(conn)) for kind, conn in cells]
    for name, arr in (point_data or {}).items():
        if np.shape(arr)[0] != len(pts):
            raise MeshError(f"point_data {name!r} has {np.shape(arr)[0]} rows, the mesh has "
                            f"{len(pts)} points")
    for name, per_block in (cell_data or {}).items():
        rows = [np.shape(a)[0] for a in per_block]
        if rows != [len(c) for _, c in blocks]:
            raise MeshError(f"cell_data {name!r} has {rows} rows per block, the cell blocks have "
                            f"{[len(c) for _, c in blocks]}")
    import meshio

    Path(p).parent.mkdir(parents=True, exist_ok=True)
    out = meshio.Mesh(pts, blocks, point_data=point_data or {}, cell_data=cell_data or {},
                      field_data=field_data or {})
    kwargs = {} if binary is None else {"binary": binary}
    if (file_format or Path(p).suffix.lower().lstrip(".")) == "vtu":
        kwargs["compression"] = COMPRESSIONS[compression]
    try:
        meshio.write(p, out, file_format=file_format, **kwargs)
    except Exception as exc:  # meshio raises plain exceptions of many kinds
        raise MeshError(f"cannot write mesh file {p}: {type(exc).__name__}: {exc}") from None
    return Path(p)


def _atomic_xml(path: Path, text: str | None = None, tree=None) -> Path:
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    if tree is not None:
        tree.write(tmp, xml_declaration=True, encoding="utf-8")
    else:
        tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)
    return path


def write_collection(path: str | os.PathLike, times: Sequence[float], files: Sequence[str]) -> Path:
    """A ParaView collection (``.pvd``) listing ``files`` at ``times`` (written atomically)."""
    from xml.sax.saxutils import quoteattr

    rows = "\n".join(f'    <DataSet timestep="{float(t)!r}" group="" part="0" file={quoteattr(f)}/>'
                     for t, f in zip(times, files))
    text = ('<?xml version="1.0"?>\n'
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            f'  <Collection>\n{rows}\n  </Collection>\n</VTKFile>\n')
    return _atomic_xml(Path(path), text=text)


def _declarations(piece: Path) -> dict[str, list[dict]]:
    """``{"PointData": [...], "CellData": [...], "Points": [...]}``: the DataArray attributes
    (type, Name, NumberOfComponents) of a ``.vtu`` piece."""
    import xml.etree.ElementTree as ET

    root = ET.parse(piece).getroot()
    grid = root.find("UnstructuredGrid/Piece")
    out = {}
    for section in ("PointData", "CellData", "Points"):
        node = grid.find(section)
        arrays = [] if node is None else node.findall("DataArray")
        out[section] = [{k: a.attrib[k] for k in ("type", "Name", "NumberOfComponents")
                         if k in a.attrib} for a in arrays]
    return out


def write_parallel_index(path: str | os.PathLike, first_piece: str | os.PathLike,
                         pieces: Sequence[str]) -> Path:
    """A ``.pvtu`` index of ``pieces`` (names relative to it), declaring the arrays that
    ``first_piece`` holds (written atomically)."""
    import xml.etree.ElementTree as ET

    decl = _declarations(Path(first_piece))
    vtk = ET.Element("VTKFile", type="PUnstructuredGrid", version="1.0", byte_order="LittleEndian")
    grid = ET.SubElement(vtk, "PUnstructuredGrid", GhostLevel="0")
    for section, tag in (("PointData", "PPointData"), ("CellData", "PCellData"),
                         ("Points", "PPoints")):
        block = ET.SubElement(grid, tag)
        for attrs in decl[section]:
            ET.SubElement(block, "PDataArray", **attrs)
    for p in pieces:
        ET.SubElement(grid, "Piece", Source=p)
    return _atomic_xml(Path(path), tree=ET.ElementTree(vtk))
