"""Outputs of a mass-spring scene: frames (.vtu + .pvd, or XDMF), energy.csv, result.json, PNG, GIF.

:func:`write_scene_outputs` builds the whole output directory under a temporary name and moves
it into place only when every file is written (:func:`femkit.io.atomic.atomic_directory`).
Under ``femkit solve`` the frames are written while the simulation runs (:class:`FrameStream`:
a writer thread fed by the simulation's ``on_record``, off the run's critical path) into that
temporary directory; the other files follow when the run ends.

Frames: one ``frames/frame_NNNNN.vtu`` per recorded step (points padded to 3D; cells are the
springs as ``line`` cells, plus the ``triangle`` cells of cloth and mesh systems; point data
``velocity`` (3D) and ``pinned``; cell data ``stretch`` = length / rest - 1 on springs, 0 on
triangles; VTK XML with raw appended binary arrays, uncompressed: :class:`femkit.mesh.vtk.VtuFrames`) and ``scene.pvd`` listing them with their times (ParaView opens the ``.pvd`` as a
time series). ``xdmf: true`` writes ``scene.xdmf`` + ``scene.h5`` (meshio's time-series writer).

Matplotlib and Pillow (pictures: :mod:`femkit.case.scene.plot`) are imported only when a PNG
or GIF is asked for; meshio only for XDMF.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence
import numpy as np

from ...interrupt import active_flag
from ...io.atomic import EARLIER_RUN, atomic_directory
from ...io.background import BackgroundWriter
from ...io.writers import write_csv
from ...dynamics.system import COMPILED_SPRINGS
from ...mesh.vtk import VtuFrames, pad3, write_collection
from .plot import write_final_png, write_gif

__all__ = ["write_scene_outputs", "FrameStream", "write_frames_vtu", "write_frames_xdmf", "write_pvd",
           "write_energy_csv", "energy_columns", "RESULT_KEYS"]

#: Top-level keys of a scene's result.json.
RESULT_KEYS = ("case", "problem", "case_file", "femkit_version", "system", "integrator",
               "linear_solver", "dt", "t_end", "steps", "steps_planned", "interrupted", "t_reached", "frames",
               "output_every", "wall_time", "step_time", "energy", "final_state",
               "momentum_final", "stability", "converged", "warnings", "timings", "files")



def _frame_cells(system, triangles) -> list[tuple[str, np.ndarray]]:
    cells = [("line", np.asarray(system.springs, dtype=np.int64))]
    if triangles is not None and len(triangles):
        cells.append(("triangle", np.asarray(triangles, dtype=np.int64)))
    return cells


def _stretch(x: np.ndarray, i: np.ndarray, j: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """``|x_j - x_i| / rest - 1`` per spring: from :data:`~femkit.dynamics.system.COMPILED_SPRINGS`
    springs one compiled pass without the GIL (the run's thread keeps stepping while the writer
    thread computes it), below NumPy; the same bits either way."""
    if len(i) >= COMPILED_SPRINGS:
        from ...dynamics.kernels.spring_kernels import spring_stretch

        return spring_stretch(np.ascontiguousarray(x, dtype=float), i, j, rest, np.empty(len(i)))
    dx = np.take(x, j, axis=0)
    dx -= np.take(x, i, axis=0)
    return np.sqrt(np.einsum("sd,sd->s", dx, dx)) / rest - 1.0


class FrameStream:
    """A run's frames, written while it runs: ``add`` is :func:`~femkit.dynamics.simulate.simulate`'s
    ``on_record``; each frame becomes ``directory/subdir/frame_NNNNN.vtu`` (the stretch computed
    and the file written by :class:`femkit.mesh.vtk.VtuFrames`) in a writer thread
    (:class:`femkit.io.background.BackgroundWriter`: bounded queue, errors raised in the run's
    thread). ``background=False`` writes each frame at once in the caller's thread: the same
    bytes. Use it as a context manager: leaving on an exception drops the queued frames and
    waits for the one being written."""

    def __init__(self, directory: str | os.PathLike, system, triangles=None, *,
                 subdir: str = "frames", background: bool = True, depth: int = 8):
        self.directory = Path(directory)
        self.subdir = subdir
        (self.directory / subdir).mkdir(parents=True, exist_ok=True)
        cells = _frame_cells(system, triangles)
        self._vtu = VtuFrames(cells)
        self._i = np.ascontiguousarray(system.springs[:, 0])
        self._j = np.ascontiguousarray(system.springs[:, 1])
        self._rest = np.asarray(system.rest, dtype=float)
        self._zeros = [np.zeros(len(c)) for _, c in cells[1:]]
        self._pinned = np.asarray(system.pinned).astype(np.int32)
        self.names: list[str] = []
        self.writer = BackgroundWriter(depth, "femkit frame writer", background)

    def add(self, k: int, t: float, x: np.ndarray, v: np.ndarray,
            point_data: dict | None = None) -> None:
        """Queue frame ``k`` (state ``x``, ``v`` at time ``t``; not modified afterwards), with
        extra ``point_data`` (barrier contact's ``contact_force``)."""
        name = f"{self.subdir}/frame_{k:05d}.vtu"
        self.writer.submit(self._write, self.directory / name, x, v, point_data)
        self.names.append(name)

    def _write(self, path: Path, x: np.ndarray, v: np.ndarray, extra=None) -> None:
        stretch = _stretch(x, self._i, self._j, self._rest)
        self._vtu.write(path, x, cell_data={"stretch": [stretch, *self._zeros]},
                        point_data={"velocity": pad3(v), "pinned": self._pinned, **(extra or {})})

    def close(self, stop=None) -> list[str]:
        """Wait for the queued frames; the relative names of those written, in order.

        ``stop`` (a :class:`~femkit.interrupt.StopFlag`) checked while waiting: once set, the
        frames not yet started are dropped (those written so far are kept and returned)."""
        return self.names[:self.writer.close(stop)]

    def __enter__(self) -> "FrameStream":
        return self

    def __exit__(self, kind, value, tb) -> None:
        if kind is not None:
            self.writer.cancel()


def write_frames_vtu(directory: str | os.PathLike, system, traj, triangles=None,
                     subdir: str = "frames", stop=None) -> list[str]:
    """One ``.vtu`` per recorded frame of ``traj`` in ``directory/subdir``, written now (the
    frames of :class:`FrameStream`, same bytes); returns their relative names.

    ``stop`` (a :class:`~femkit.interrupt.StopFlag`) is checked before each frame: once set,
    the frames written so far are returned (a Ctrl-C while frames are written is answered)."""
    with FrameStream(directory, system, triangles, subdir=subdir, background=False) as frames:
        for k in range(len(traj.times)):
            if stop:
                break
            frames.add(k, float(traj.times[k]), traj.x[k], traj.v[k])
        return frames.close()


def write_pvd(path: str | os.PathLike, times: Sequence[float], files: Sequence[str]) -> Path:
    """A ParaView collection listing ``files`` at ``times`` (:func:`femkit.mesh.vtk.write_collection`)."""
    return write_collection(path, times, files)


def write_frames_xdmf(path: str | os.PathLike, system, traj, triangles=None) -> Path:
    """An XDMF time series (``.xdmf`` + ``.h5``): the first frame's mesh, positions per step.

    Point data per time: ``position`` (3D), ``displacement`` from the first frame and
    ``velocity`` (ParaView's "Warp By Vector" on ``displacement`` animates it). The springs
    are ``line`` cells; a scene with triangles (a cloth) gets XDMF's ``Mixed`` topology of
    both (:func:`_series_writer`), which meshio's ``TimeSeriesReader`` reads back as the two
    blocks.
    """
    cells = _frame_cells(system, triangles)
    x0 = pad3(traj.x[0])
    path = Path(path).resolve()
    # meshio 5 opens the .h5 by its bare name, i.e. in the current directory: write from there
    # (os.chdir and back: contextlib.chdir needs Python 3.11)
    cwd = os.getcwd()
    os.chdir(path.parent)
    try:
        with _series_writer()(str(path)) as w:
            w.write_points_cells(x0, cells)
            for k, t in enumerate(traj.times):
                x = pad3(traj.x[k])
                w.write_data(float(t), point_data={"position": x, "displacement": x - x0,
                                                   "velocity": pad3(traj.v[k])})
    finally:
        os.chdir(cwd)
    return path


def _mixed_topology(cells: Sequence[tuple[str, np.ndarray]]) -> np.ndarray:
    """The one-dimensional ``Mixed`` topology of XDMF's model: per cell its type index, for a
    ``line`` (XDMF's polyline) its node count 2, then its node ids ("XDMF Model and Format",
    section "Topology", arbitrary; the layout meshio's ``translate_mixed_cells`` reads).

    >>> _mixed_topology([("line", np.array([[0, 1]])), ("triangle", np.array([[0, 1, 2]]))])
    array([2, 2, 0, 1, 4, 0, 1, 2])
    """
    from meshio.xdmf.common import meshio_type_to_xdmf_index

    rows = []
    for kind, conn in cells:
        conn = np.asarray(conn, dtype=np.int64).reshape(len(conn), -1)
        lead = [meshio_type_to_xdmf_index[kind]] + ([conn.shape[1]] if kind == "line" else [])
        rows.append(np.column_stack([np.tile(np.array(lead, np.int64), (len(conn), 1)), conn]).ravel())
    return np.concatenate(rows) if rows else np.zeros(0, np.int64)


def _series_writer():
    """meshio's XDMF ``TimeSeriesWriter`` whose mesh of several cell blocks is written as
    :func:`_mixed_topology`: meshio's own (5.3.0 to 5.3.5, ``xdmf/time_series.py``) prefixes
    the line count in place (``c.data[:] = np.insert(c.data, 0, 2, axis=1)``), which cannot
    fit an ``(n, 2)`` block, so any mesh with lines and another cell type fails after the run
    ("could not broadcast (n,3) into (n,2)"). One block: meshio's writer unchanged."""
    from xml.etree import ElementTree as ET

    import meshio
    from meshio.xdmf.common import numpy_to_xdmf_dtype

    class _Writer(meshio.xdmf.TimeSeriesWriter):
        def cells(self, cells, grid):
            if len(cells) < 2:
                return super().cells(cells, grid)
            data = _mixed_topology(cells)
            topo = ET.SubElement(grid, "Topology", TopologyType="Mixed",
                                 NumberOfElements=str(sum(len(c) for _, c in cells)))
            dt, prec = numpy_to_xdmf_dtype[data.dtype.name]
            item = ET.SubElement(topo, "DataItem", DataType=dt, Dimensions=str(len(data)),
                                 Format=self.data_format, Precision=prec)
            item.text = self.numpy_to_xml_string(data)
            return None

    return _Writer


def energy_columns(dim: int) -> list[str]:
    """Header of energy.csv."""
    return (["t", "kinetic", "spring", "gravity", "contact", "total"]
            + [f"momentum_{c}" for c in "xyz"[:dim]])


def write_energy_csv(path: str | os.PathLike, traj) -> Path:
    """``energy.csv``: one row per recorded frame (see :func:`energy_columns`)."""
    dim = traj.momentum.shape[1]
    e = traj.energies
    table = np.column_stack([traj.times] + [e[k] for k in ("kinetic", "spring", "gravity",
                                                           "contact", "total")]
                            + [traj.momentum[:, c] for c in range(dim)])
    columns = energy_columns(dim)
    return write_csv(path, [dict(zip(columns, map(float, row))) for row in table],
                     columns=columns, float_format=".17g")


# ----------------------------------------------------------------------------- all

def write_scene_outputs(result, directory: str | os.PathLike, *, into: Path | None = None,
                        frames: FrameStream | None = None) -> Path:
    """Write every requested output of ``result`` (a SceneResult) into ``directory`` atomically.

    ``into``: the temporary directory of an :func:`~femkit.io.atomic.atomic_directory` the
    caller holds open (its run's), where ``frames`` (a :class:`FrameStream`) has been writing
    the frames during the run; the remaining files go there and the caller moves it into place.
    Without it the directory is built here, frames included."""
    final = Path(directory).resolve()
    result.output_dir = final
    if into is not None:
        _write_outputs(result, Path(into), frames)
        return final
    with atomic_directory(final, EARLIER_RUN) as tmp:
        _write_outputs(result, tmp, None)
    return final


def _write_outputs(result, tmp: Path, stream: FrameStream | None) -> None:
    opts = result.case.spec.output
    traj, system, tri = result.trajectory, result.system, result.triangles
    files: list[str] = []
    stop = active_flag()
    stopped = bool(stop)   # a stop request answered: the pictures (seconds of plotting) are skipped
    if stop:  # the simulation itself was stopped: write every frame it recorded
        stop = None
    if opts.vtu:
        if stream is None:
            frames = write_frames_vtu(tmp, system, traj, tri, stop=stop)
        else:  # written during the run: wait for the last ones (a stop request is answered)
            frames = stream.close(stop)
        write_pvd(tmp / "scene.pvd", traj.times[:len(frames)], frames)
        files += ["scene.pvd", *frames]
        if stop:  # stopped while writing frames: keep those, skip the pictures
            result.output_stop = stop.name
            result.frames_written = len(frames)
    if opts.xdmf and not stop:
        write_frames_xdmf(tmp / "scene.xdmf", system, traj, tri)
        files += ["scene.xdmf", "scene.h5"]
    if opts.energy_csv:
        write_energy_csv(tmp / "energy.csv", traj)
        files.append("energy.csv")
    if opts.png and not stop and not stopped:
        write_final_png(tmp / "final.png", system, traj, result.case.name, triangles=tri)
        files.append("final.png")
    if opts.gif and not stop and not stopped:
        write_gif(tmp / "animation.gif", system, traj, result.case.name, triangles=tri)
        files.append("animation.gif")
    result.write_result_json(tmp, [*files, "result.json"])
