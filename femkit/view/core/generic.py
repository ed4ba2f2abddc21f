"""The picture of a run directory by its files alone: its ``.pvd`` time series, else its
``solution.vtu``, coloured by a point or cell array (a vector by its length).

Any kind that writes a PVD collection of VTU frames (a heat or wave run, a scene, a solid) is
drawn this way without code of its own; kinds with more to show declare a view function
(:attr:`femkit.kinds.Kind.view`) and reuse :func:`read_series` and :func:`field_names`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from ...errors import InputError
from .picture import Frame, Layer, Picture
from .render import pyvista
from .source import Run, check_field

__all__ = ["read_pvd", "read_series", "field_names", "flat", "colour_by", "surface",
           "generic_picture"]

#: Arrays that are bookkeeping, not fields (gmsh's tags).
HIDDEN = ("gmsh:physical", "gmsh:geometrical", "vtkOriginalPointIds", "vtkOriginalCellIds")


def read_pvd(path: Path) -> list[tuple[float, Path]]:
    """The ``(time, file)`` of every data set a ``.pvd`` collection lists, in order."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise InputError(f"{path}: not a readable PVD collection ({exc})") from None
    out = [(float(d.get("timestep", "nan")), path.parent / d.get("file", ""))
           for d in root.iter("DataSet")]
    if not out:
        raise InputError(f"{path}: the collection lists no data set")
    return out


def read_series(path: Path, limit: int | None = None) -> list[tuple[float, object]]:
    """The frames of a ``.pvd`` as ``(time, pyvista dataset)``; with ``limit`` at most that many,
    evenly spaced, the first and the last among them."""
    pv = pyvista()
    items = read_pvd(path)
    if limit is not None and len(items) > limit:
        picks = np.unique(np.linspace(0, len(items) - 1, limit).round().astype(int))
        items = [items[i] for i in picks]
    frames = []
    for t, file in items:
        if not file.is_file():
            raise InputError(f"{path}: lists {file.name}, which is missing")
        frames.append((t, pv.read(file)))
    return frames


def field_names(mesh) -> list[str]:
    """The arrays of ``mesh`` that can colour it (point data first), bookkeeping left out."""
    names = list(mesh.point_data.keys()) + list(mesh.cell_data.keys())
    return [n for n in dict.fromkeys(names) if n not in HIDDEN]


def flat(mesh) -> bool:
    """Whether ``mesh`` lies in a plane z = const (drawn from +z with x and y axes)."""
    z = np.asarray(mesh.points)[:, 2]
    return bool(z.size == 0 or np.ptp(z) <= 1e-12 * max(1.0, float(np.abs(z).max())))


def colour_by(mesh, name: str) -> str:
    """The name of the scalar array ``name`` colours ``mesh`` by: itself, or for a vector its
    length, stored as ``|name|``."""
    data = mesh.point_data if name in mesh.point_data else mesh.cell_data
    values = np.asarray(data[name])
    if values.ndim == 1:
        return name
    data[f"|{name}|"] = np.linalg.norm(values.reshape(len(values), -1), axis=1)
    return f"|{name}|"


def generic_picture(run: Run, field: str | None = None, limit: int = 60) -> Picture:
    """The run directory's ``.pvd`` time series (at most ``limit`` frames), else its
    ``solution.vtu``, coloured by ``field`` (default: the first point array)."""
    directory = run.directory
    if directory is None:
        raise InputError(f"{run.name}: the run wrote no files to draw")
    pvds = sorted(directory.glob("*.pvd"))
    if pvds:
        series = read_series(pvds[0], limit)
    else:
        series = [(None, pyvista().read(run.file("solution.vtu")))]
    fields = field_names(series[0][1])
    if not fields:
        raise InputError(f"{directory}: its files hold no field to colour by")
    name = check_field(field, fields, fields[0])
    frames = [Frame([Layer(mesh, scalars=colour_by(mesh, name), title=name, edges=False)], t)
              for t, mesh in series]
    return Picture(frames, title=f"{run.name}: {name}", dim=2 if flat(series[0][1]) else 3,
                   field=name, fields=tuple(fields))


def surface(mesh):
    """The boundary surface of ``mesh`` (pyvista's ``extract_surface``, its algorithm named
    where this pyvista asks for it)."""
    try:
        return mesh.extract_surface(algorithm="dataset_surface")
    except TypeError:  # pyvista < 0.47 has one algorithm
        return mesh.extract_surface()
