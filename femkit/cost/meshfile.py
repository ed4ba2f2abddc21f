"""Size of a mesh file's mesh without reading it (for the plan of a run that reads one).

An ASCII gmsh file announces its element count in the line after ``$Elements`` (format 2.2:
the count; 4.1: ``numEntityBlocks numElements ...``); the count includes the boundary lines,
a few percent of the triangles, so it is a slight overestimate. Other files (binary ``.msh``,
``.vtu``, ``.xdmf``) are estimated from their size at ``BYTES_PER_TRIANGLE``.

>>> import tempfile, os
>>> p = os.path.join(tempfile.mkdtemp(), "m.msh")
>>> _ = open(p, "w").write("$MeshFormat\\n4.1 0 8\\n$EndMeshFormat\\n$Elements\\n2 1200 1 1200\\n")
>>> msh_triangle_count(p)
(1200, 'the $Elements header')
"""

from __future__ import annotations

import os

__all__ = ["msh_triangle_count", "msh_has_volume", "BYTES_PER_TRIANGLE"]

#: File bytes per triangle when only the size is known (ASCII .msh 4.1 written by femkit: ~95;
#: .vtu with data: ~50); the smaller value, so the estimate errs on the large side.
BYTES_PER_TRIANGLE = 50.0


def msh_triangle_count(path: str | os.PathLike, max_scan: int = 1 << 26) -> tuple[int, str]:
    """``(triangles, how)``: the element count announced by an ASCII ``.msh``, else a size estimate.

    Reads lines until ``$Elements`` (at most ``max_scan`` bytes), never the element data.
    """
    p = os.fspath(path)
    size = os.path.getsize(p)
    estimate = (max(int(size / BYTES_PER_TRIANGLE), 1), f"the file size ({size} bytes)")
    if not p.lower().endswith(".msh"):
        return estimate
    scanned = 0
    try:
        with open(p, "rb") as fh:
            fmt = None
            for raw in fh:
                scanned += len(raw)
                if scanned > max_scan:
                    break
                line = raw.strip()
                if fmt is None and line and line[:1].isdigit():
                    parts = line.split()
                    fmt = parts[0].decode("ascii", "replace")
                    if len(parts) > 1 and parts[1] != b"0":  # binary file: counts are not text
                        return estimate
                if line == b"$Elements":
                    nums = fh.readline().split()
                    count = int(nums[1] if fmt and fmt.startswith("4") else nums[0])
                    return (max(count, 1), "the $Elements header")
                if fmt is not None and line == b"$Nodes":
                    nums = _line_after(fh, b"$Elements", max_scan - scanned)
                    if nums is None:
                        return estimate
                    count = int(nums[1] if fmt.startswith("4") else nums[0])
                    return (max(count, 1), "the $Elements header")
    except (OSError, ValueError, IndexError):
        return estimate
    return estimate


def _line_after(fh, header: bytes, budget: int) -> list | None:
    """The fields of the line after the line ``header`` (``$Elements``, not ``$ElementData``),
    found by reading blocks of a MiB (the node section is skipped without splitting it into
    lines); None past ``budget`` bytes or at the end of the file."""
    key = b"\n" + header
    buf, read = b"", 0
    while read <= budget:
        chunk = fh.read(1 << 20)
        read += len(chunk)
        buf += chunk
        at = buf.find(key)
        while at >= 0:
            lines = buf[at + 1:].split(b"\n", 2)
            if len(lines) < 3 and chunk:
                break                      # the next line is in the next block
            if lines[0].strip() == header and len(lines) > 1:
                return lines[1].split()
            at = buf.find(key, at + 1)
        if not chunk:
            return None
        buf = buf[max(0, len(buf) - 256):] if at < 0 else buf[at:]
    return None


def msh_has_volume(path: str | os.PathLike, max_scan: int = 1 << 26) -> bool:
    """Whether an ASCII ``.msh`` file holds a volume (tetrahedra), read from its header only:
    format 4.1 counts its volumes in the line after ``$Entities``; format 2.2 has no entities,
    so its element lines are scanned for type 4 (a tetrahedron), at most ``max_scan`` bytes.
    False when unknown (binary, other formats): the file is priced as triangles."""
    p = os.fspath(path)
    if not p.lower().endswith(".msh"):
        return False
    scanned, in_elements = 0, False
    try:
        with open(p, "rb") as fh:
            for raw in fh:
                scanned += len(raw)
                if scanned > max_scan:
                    break
                line = raw.strip()
                if line == b"$Entities":
                    return int(fh.readline().split()[3]) > 0
                if line == b"$Elements":
                    fh.readline()
                    in_elements = True
                elif in_elements:
                    parts = line.split()
                    if line.startswith(b"$") or len(parts) < 2:
                        return False
                    if parts[1] == b"4":
                        return True
    except (OSError, ValueError, IndexError):
        return False
    return False
