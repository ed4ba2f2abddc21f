"""femkit's one VTK writer: points, cell blocks and data to ``.vtu`` (or any meshio format),
and the two XML index files ParaView opens over several ``.vtu`` files.

* :func:`write_cells` writes a Poisson solution (:func:`femkit.mesh.write_mesh`) and each
  rank's piece of a distributed solution: an uncompressed ``.vtu`` with its arrays appended
  raw (at disk speed), other formats and compressions through meshio;
* :class:`VtuFrames` writes a scene's frames (springs as ``line`` cells, cloth triangles), the
  cells encoded once; both ``.vtu`` writers share :func:`_appended_header` and
  :func:`_write_appended`;
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
import sys
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import MeshError

__all__ = ["write_cells", "write_collection", "write_parallel_index", "pad3", "vtu_header",
           "reappended", "Later", "COMPRESSIONS", "DEFAULT_COMPRESSION"]

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


class Later:
    """A data array whose values another thread hands over while its file is being written
    (a Poisson run's error indicators, known after the solution file was begun).

    Its rows and type are known at once, so the ``.vtu`` declares it and its bytes are a hole
    that is filled when :meth:`get` returns (the raw appended writer: everything else is
    written first; other formats and compressions wait for it before writing anything).
    :meth:`set` hands the values over; :meth:`abandon` makes a waiting :meth:`get` fail (the
    run failed, nothing is to be written).

    Parameters
    ----------
    rows : int
        The array's length.
    dtype : numpy dtype
        Its type (one of VTK's; float64 by default).
    """

    _POLL = 0.05  # seconds between looks, so a cancelled writer is never stuck here

    def __init__(self, rows: int, dtype=np.float64):
        import threading

        self.shape = (int(rows),)
        self.dtype = np.dtype(dtype)
        self.nbytes = self.shape[0] * self.dtype.itemsize
        self.ndim = 1
        self._ready = threading.Event()
        self._value: np.ndarray | None = None

    def set(self, values) -> None:
        """Hand the values over (``rows`` of them, cast to the declared type)."""
        a = np.asarray(values, dtype=self.dtype)
        if a.shape != self.shape:
            raise MeshError(f"a data array declared with {self.shape[0]} rows was given "
                            f"{a.shape[0] if a.ndim else 0}")
        self._value = a
        self._ready.set()

    def abandon(self) -> None:
        """Make :meth:`get` fail: the values will never come."""
        self._ready.set()

    def get(self) -> np.ndarray:
        """The values, once :meth:`set` gave them (waiting until then)."""
        while not self._ready.wait(self._POLL):
            pass
        if self._value is None:
            raise MeshError("the file was abandoned before its last array was given")
        return self._value


def _resolved(data: dict | None) -> dict:
    """``data`` with every :class:`Later` replaced by its values (waiting for them)."""
    return {name: ([p.get() if isinstance(p, Later) else p for p in v] if isinstance(v, list)
                   else v.get() if isinstance(v, Later) else v)
            for name, v in (data or {}).items()}


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
    Path(p).parent.mkdir(parents=True, exist_ok=True)
    fmt = file_format or Path(p).suffix.lower().lstrip(".")
    if fmt == "vtu" and COMPRESSIONS[compression] is None and binary is not False:
        try:
            _write_vtu_raw(p, pts, blocks, point_data or {}, cell_data or {})
        except OSError as exc:
            raise MeshError(f"cannot write mesh file {p}: {type(exc).__name__}: {exc}") from None
        return Path(p)
    import meshio

    out = meshio.Mesh(pts, blocks, point_data=_resolved(point_data),
                      cell_data=_resolved(cell_data), field_data=field_data or {})
    kwargs = {} if binary is None else {"binary": binary}
    if (file_format or Path(p).suffix.lower().lstrip(".")) == "vtu":
        kwargs["compression"] = COMPRESSIONS[compression]
    try:
        meshio.write(p, out, file_format=file_format, **kwargs)
    except Exception as exc:  # meshio raises plain exceptions of many kinds
        raise MeshError(f"cannot write mesh file {p}: {type(exc).__name__}: {exc}") from None
    return Path(p)


#: VTK's names of the array types the writer stores.
_VTK_TYPES = {np.dtype(t): name for t, name in (
    (np.float64, "Float64"), (np.float32, "Float32"), (np.int8, "Int8"), (np.int16, "Int16"),
    (np.int32, "Int32"), (np.int64, "Int64"), (np.uint8, "UInt8"), (np.uint16, "UInt16"),
    (np.uint32, "UInt32"), (np.uint64, "UInt64"))}

#: Rows of the padded (n, 3) points converted per write (bounded temporary).
_ROWS = 1 << 20


def _native(a: np.ndarray, contiguous: bool = True) -> np.ndarray:
    """``a`` as a native-order array of one of VTK's types (booleans as UInt8, other types as
    Int64 or Float64), C-contiguous unless ``contiguous`` is false (a broadcast constant stays
    a view: :func:`_write_appended` writes it a block of rows at a time)."""
    if isinstance(a, Later):
        return a  # written when its values come (:func:`_write_appended`)
    a = np.asarray(a)
    if a.dtype == bool:
        a = a.astype(np.uint8)
    elif a.dtype.newbyteorder("=") not in _VTK_TYPES:
        a = a.astype(np.int64 if a.dtype.kind in "iu" else np.float64)
    a = a.astype(a.dtype.newbyteorder("="), copy=False)
    return np.ascontiguousarray(a) if contiguous else a


def _write_vtu_raw(path: str, points: np.ndarray, blocks: list, point_data: dict,
                   cell_data: dict) -> None:
    """An uncompressed ``.vtu`` with its arrays appended raw after the XML (VTK's
    ``<AppendedData encoding="raw">``, UInt64 size headers): the bytes of each array go to the
    file as they are in memory (no base64 text, no concatenated copies), so it is written at
    disk speed. ParaView and meshio read it; :func:`vtu_header` parses its XML part."""
    arrays = []          # (section, name, vtk type, components, [pieces], total bytes)

    def add(section, name, pieces, comps=None):
        pieces = [_native(a, contiguous=False) for a in pieces]
        dtypes = {a.dtype for a in pieces}
        if len(dtypes) > 1:
            if any(isinstance(a, Later) for a in pieces):
                raise MeshError(f"{section} array {name!r}: its pieces' types differ")
            common = np.result_type(*dtypes)
            pieces = [a.astype(common) for a in pieces]
        dtype = pieces[0].dtype
        if dtype not in _VTK_TYPES:
            raise MeshError(f"cannot write {section} array {name!r} of type {dtype} to a .vtu file")
        arrays.append((section, name, _VTK_TYPES[dtype], comps, pieces,
                       sum(a.nbytes for a in pieces)))

    conn = [_native(c) for _, c in blocks]
    total = sum(c.size for c in conn)
    # Int32 connectivity and offsets whenever the ids fit (VTK's and ParaView's usual type):
    # half the bytes of Int64, converted a block of rows at a time (bounded temporary)
    idx = np.dtype(np.int32) if max(len(points), total) <= np.iinfo(np.int32).max else np.dtype(np.int64)

    def connectivity():
        for c in conn:
            for lo in range(0, len(c), _ROWS):
                yield c[lo:lo + _ROWS].astype(idx, copy=False).ravel()

    def offsets():
        ends = 0
        for c in conn:
            w = c.shape[1]
            for lo in range(0, len(c), _ROWS):
                yield ends + w * np.arange(lo + 1, min(lo + _ROWS, len(c)) + 1, dtype=idx)
            ends += c.size

    cell_arrays = [("Cells", "connectivity", _VTK_TYPES[idx], None, connectivity(), total * idx.itemsize),
                   ("Cells", "offsets", _VTK_TYPES[idx], None, offsets(),
                    sum(len(c) for c in conn) * idx.itemsize)]
    add("Cells", "types", [np.full(len(c), _vtk_cell_type(kind), np.uint8)
                           for (kind, _), c in zip(blocks, conn)])
    for name, a in point_data.items():
        a = a if isinstance(a, Later) else np.asarray(a)
        add("PointData", name, [a], a.shape[1] if a.ndim == 2 else None)
    for name, per_block in cell_data.items():
        a0 = per_block[0] if isinstance(per_block[0], Later) else np.asarray(per_block[0])
        add("CellData", name, list(per_block), a0.shape[1] if a0.ndim == 2 else None)

    pts = np.asarray(points, dtype=np.float64)

    def padded():  # padded to 3D a block at a time (bounded temporary)
        for lo in range(0, len(pts), _ROWS):
            yield pad3(pts[lo:lo + _ROWS])

    declared = {"Points": [("Points", "Float64", 3, 3 * len(pts) * 8)],
                "Cells": [], "PointData": [], "CellData": []}
    arrays = cell_arrays + arrays  # connectivity, offsets, types, the data
    for section, name, vtype, comps, _, nbytes in arrays:
        declared[section].append((name, vtype, comps, nbytes))
    header = _appended_header(len(pts), sum(len(c) for c in conn), declared)
    with open(path, "wb") as f:
        _write_appended(f, header, [(3 * len(pts) * 8, padded())]
                        + [(nbytes, pieces) for *_, pieces, nbytes in arrays])


def _appended_header(n_points: int, n_cells: int, declared: dict) -> bytes:
    """The XML part of a ``.vtu`` whose arrays are appended raw (VTK's ``<AppendedData
    encoding="raw">``, UInt64 size headers; Kitware, "VTK File Formats", "XML File Formats").
    ``declared``: ``{section: [(name, VTK type, components or None, bytes), ...]}`` for the
    sections ``Points``, ``Cells``, ``PointData``, ``CellData``, in the order declared.

    The arrays are appended in the *reverse* of the order they are declared (the last
    declared at offset 0, the ``Points`` last; :func:`_write_appended` writes them so), the
    layout meshio's reader of raw appended data needs to read every file. That reader (meshio
    5.3.0 to 5.3.5 and its main branch alike, ``meshio/vtu/_vtu.py``, ``_parse_raw_binary``)
    walks the appended bytes in file order; for the array at raw offset ``i`` it looks up
    ``root.find(".//DataArray[@offset='i']")``, the first such ``DataArray`` *in document
    order*, then rewrites that element's offset to the array's position in a base64 string it
    builds. Declared in file order, an array read earlier (earlier in the document) whose
    rewritten offset happens to equal a later array's raw offset is found instead of it, and
    the file is refused or misread: a coincidence of sizes (a Poisson solution on 5 x 5
    points with no boundary lines; 17 of the 450 grids of up to 15 x 15 squares, with and
    without boundary lines). Appended in reverse, when the array at ``i`` is looked up the
    elements carrying ``offset="i"`` are that array (raw offsets strictly increase: every
    array has an 8-byte size header) and arrays already read, each of which lies *after* it in
    the document; ``find`` returns it. VTK seeks each array by its offset, in any order. The
    bytes written are the same as in file order: the layout costs nothing.
    """
    items = [(section, entry) for section in ("Points", "Cells", "PointData", "CellData")
             for entry in declared.get(section, ())]
    offsets, end = [0] * len(items), 0
    for j in range(len(items) - 1, -1, -1):   # the last declared first in the file
        offsets[j] = end
        end += items[j][1][3] + 8              # + the UInt64 size header
    order = "LittleEndian" if sys.byteorder == "little" else "BigEndian"
    xml = ['<?xml version="1.0"?>',
           f'<VTKFile type="UnstructuredGrid" version="1.0" byte_order="{order}" '
           'header_type="UInt64">',
           "<UnstructuredGrid>",
           f'<Piece NumberOfPoints="{n_points}" NumberOfCells="{n_cells}">']
    j = 0
    for section in ("Points", "Cells", "PointData", "CellData"):
        if not declared.get(section) and section not in ("Points", "Cells"):
            continue
        xml.append(f"<{section}>")
        for name, vtype, comps, _ in declared.get(section, ()):
            nc = f' NumberOfComponents="{comps}"' if comps else ""
            xml.append(f'<DataArray type="{vtype}" Name="{_attr(name)}"{nc} '
                       f'format="appended" offset="{offsets[j]}"/>')
            j += 1
        xml.append(f"</{section}>")
    xml += ["</Piece>", "</UnstructuredGrid>", '<AppendedData encoding="raw">', "_"]
    return "\n".join(xml).encode()


def _write_appended(f, header: bytes, arrays: list) -> None:
    """Write ``header`` (:func:`_appended_header`) and each ``(bytes, pieces)`` of ``arrays``
    (given in the order declared, written in reverse: see :func:`_appended_header`): its
    UInt64 size, then the pieces' memory as it is (no copy, no encoding; a piece that is
    not contiguous, e.g. a broadcast constant, a block of rows at a time)."""
    holes = []  # (file position, Later): filled last, when their values have come
    f.write(header)
    for nbytes, pieces in reversed(arrays):
        f.write(np.uint64(nbytes).tobytes())
        for a in pieces:
            if isinstance(a, Later):
                holes.append((f.tell(), a))
                f.seek(a.nbytes, os.SEEK_CUR)
            elif a.flags.c_contiguous:
                f.write(memoryview(a).cast("B"))
            else:
                for lo in range(0, len(a), _ROWS):
                    f.write(memoryview(np.ascontiguousarray(a[lo:lo + _ROWS])).cast("B"))
    f.write(b"\n</AppendedData>\n</VTKFile>\n")
    for at, later in holes:
        f.seek(at)
        f.write(memoryview(_native(later.get().astype(later.dtype, copy=False))).cast("B"))


#: VTK's cell type numbers of the cells femkit writes (others: meshio's table).
_CELL_TYPES = {"vertex": 1, "line": 3, "triangle": 5, "quad": 9, "tetra": 10, "hexahedron": 12,
               "triangle6": 22, "tetra10": 24,
               "wedge": 13, "pyramid": 14}


def _vtk_cell_type(kind: str) -> int:
    if kind in _CELL_TYPES:
        return _CELL_TYPES[kind]
    from meshio._vtk_common import meshio_to_vtk_type

    try:
        return meshio_to_vtk_type[kind]
    except KeyError:
        raise MeshError(f"unknown cell type {kind!r} for a .vtu file") from None


#: XML attribute escapes (what ``xml.sax.saxutils.quoteattr`` escapes, the double quote always:
#: the attributes are written inside double quotes); here, because importing ``xml.sax``
#: imports ``urllib.request`` and ``http.client``, ~20 ms of every run that writes a VTU
_ATTR_ESCAPES = (("&", "&amp;"), ("<", "&lt;"), (">", "&gt;"), ('"', "&quot;"),
                 ("\n", "&#10;"), ("\r", "&#13;"), ("\t", "&#9;"))


def _attr(text: str) -> str:
    s = str(text)
    for raw, escaped in _ATTR_ESCAPES:
        s = s.replace(raw, escaped)
    return s


#: numpy types of the block-size headers of appended data (VTKFile's ``header_type``)
_HEADER_TYPES = {"UInt32": np.uint32, "UInt64": np.uint64}


def reappended(raw: bytes, reverse: bool = True) -> bytes | None:
    """The bytes of a ``.vtu`` file with its raw appended arrays re-appended in the reverse of
    their declaration (the layout meshio reads at every size, see :func:`_appended_header`;
    ``reverse=False``: in their declared order), the offsets rewritten to match; ``None`` when
    ``raw`` holds no uncompressed raw appended data or cannot be parsed.

    It lets femkit read the ``.vtu`` files written before it appended in reverse (and any other
    writer's raw appended file that meshio misreads): the arrays' bytes are moved, not decoded.
    """
    import xml.etree.ElementTree as ET

    start = raw.find(b"<AppendedData")
    opened = raw.find(b">", start) + 1
    if start < 0 or b'"raw"' not in raw[start:opened]:
        return None
    first = raw.find(b"_", opened) + 1
    try:
        root = ET.fromstring(raw[:start] + b"</VTKFile>")
        if root.get("compressor"):
            return None
        size = np.dtype(_HEADER_TYPES[root.get("header_type", "UInt32")]).newbyteorder(
            ">" if root.get("byte_order") == "BigEndian" else "<")
        arrays = [a for a in root.iter("DataArray") if a.get("format") == "appended"]
        blocks = []
        for a in arrays:
            at = first + int(a.get("offset"))
            n = int(np.frombuffer(raw, size, 1, at)[0])
            if at + size.itemsize + n > len(raw):
                return None
            blocks.append(raw[at:at + size.itemsize + n])
    except (ET.ParseError, KeyError, ValueError, TypeError):
        return None
    order = list(range(len(arrays)))[::-1 if reverse else 1]
    offset = 0
    for j in order:
        arrays[j].set("offset", str(offset))
        offset += len(blocks[j])
    head = ET.tostring(root).rsplit(b"</VTKFile>", 1)[0]
    return b"".join([b'<?xml version="1.0"?>\n', head, b'<AppendedData encoding="raw">\n_']
                    + [blocks[j] for j in order] + [b"\n</AppendedData>\n</VTKFile>\n"])


def vtu_header(path: str | os.PathLike):
    """The XML of a ``.vtu`` file without its appended raw data, as an ElementTree root
    (the whole file when it has no raw section)."""
    import xml.etree.ElementTree as ET

    with open(path, "rb") as f:
        head = f.read(1 << 20)
    cut = head.find(b"<AppendedData")
    if cut < 0:
        return ET.parse(path).getroot()
    return ET.fromstring(head[:cut] + b"</VTKFile>")


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
    root = vtu_header(piece)
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


# ----------------------------------------------------------------------------- frame series
__all__ += ["VtuFrames"]

class VtuFrames:
    """``.vtu`` files of a time series whose cells never change (a scene's frames), written at
    disk speed: VTK's XML format with the arrays as *raw appended* binary (``<AppendedData
    encoding="raw">``, UInt64 block headers; Kitware, "VTK File Formats", section "XML File
    Formats"), no base64 and no compression. The connectivity, offsets and types are encoded
    once; each frame writes its XML header and then its arrays straight from memory. ParaView
    and meshio read these files like any ``.vtu``.

    ``cells`` is ``[(meshio type, (k, nv) ints), ...]`` as for :func:`write_cells`;
    :meth:`write` takes the points ``(n, d)``, ``point_data`` ``{name: (n,) or (n, c)}`` and
    ``cell_data`` ``{name: [one array per block]}``.
    """

    def __init__(self, cells: Sequence[tuple[str, np.ndarray]]):
        unknown = [kind for kind, _ in cells if kind not in _CELL_TYPES]
        if unknown:
            raise MeshError(f"frame series: cell type {unknown[0]!r} not supported; valid: "
                            f"{', '.join(_CELL_TYPES)}")
        blocks = [(kind, np.asarray(conn)) for kind, conn in cells]
        self.rows = [len(c) for _, c in blocks]
        self.n_cells = sum(self.rows)
        conn = [c.reshape(len(c), -1) for _, c in blocks]
        sizes = np.concatenate([np.full(len(c), c.shape[1], dtype=np.int64) for c in conn]) \
            if conn else np.zeros(0, dtype=np.int64)
        # Int32 connectivity and offsets while they fit (VTK reads either): a third less to write
        top = max([sum(c.size for c in conn)] + [int(c.max()) + 1 for c in conn if c.size])
        index = np.int32 if top < 2 ** 31 else np.int64
        self._topology = (
            _native(np.concatenate([c.ravel() for c in conn]).astype(index) if conn
                    else np.zeros(0, index)),
            _native(np.cumsum(sizes).astype(index)),
            _native(np.concatenate([np.full(len(c), _CELL_TYPES[k], dtype=np.uint8)
                                    for (k, _), c in zip(blocks, conn)])
                    if conn else np.zeros(0, np.uint8)))
        self._layout: tuple | None = None
        self._header = b""

    def _xml(self, n_points: int, point: list, cell: list) -> bytes:
        def declare(items):
            return [(name, _VTK_TYPES[a.dtype], a.shape[1] if a.ndim == 2 else None, a.nbytes)
                    for name, a in items]

        conn, offs, types = self._topology
        return _appended_header(n_points, self.n_cells, {
            "Points": [("Points", "Float64", 3, point[0][1].nbytes)],
            "Cells": declare([("connectivity", conn), ("offsets", offs), ("types", types)]),
            "PointData": declare(point[1:]), "CellData": declare(cell)})

    def write(self, path: str | os.PathLike, points: np.ndarray, *,
              point_data: dict | None = None, cell_data: dict | None = None) -> Path:
        """Write one frame to ``path`` (its directory must exist).

        Raises
        ------
        MeshError
            A data array whose row count does not match, or the file cannot be written
            (the operating system's reason).
        """
        pts = _native(pad3(points))
        point = [("Points", pts)]
        for name, a in (point_data or {}).items():
            a = _native(a)
            if a.shape[0] != len(pts):
                raise MeshError(f"point_data {name!r} has {a.shape[0]} rows, the frame has "
                                f"{len(pts)} points")
            point.append((name, a))
        cell = []
        for name, per_block in (cell_data or {}).items():
            rows = [np.shape(a)[0] for a in per_block]
            if rows != self.rows:
                raise MeshError(f"cell_data {name!r} has {rows} rows per block, the cell blocks "
                                f"have {self.rows}")
            cell.append((name, _native(np.concatenate([np.asarray(a) for a in per_block]))))
        layout = tuple((name, a.dtype.str, a.shape) for name, a in point + cell)
        if layout != self._layout:
            self._layout, self._header = layout, self._xml(len(pts), point, cell)
        conn, offs, types = self._topology
        arrays = [pts, conn, offs, types] + [a for _, a in point[1:]] + [a for _, a in cell]
        try:
            with open(path, "wb") as fh:
                _write_appended(fh, self._header, [(a.nbytes, [a]) for a in arrays])
        except OSError as exc:
            raise MeshError(f"cannot write frame {os.fspath(path)}: "
                            f"{exc.strerror or exc}") from None
        return Path(path)
