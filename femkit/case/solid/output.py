"""Outputs of a solid run: VTU frames + ``solid.pvd``, ``result.json``, ``deformed.png``,
``animation.gif``, written into a temporary directory moved into place when complete
(:func:`femkit.io.atomic.atomic_directory`).

Each frame ``frames/frame_NNNNN.vtu`` (femkit's one VTK writer, :func:`femkit.mesh.vtk.write_cells`)
holds the rest mesh (``tetra`` or ``triangle`` cells) with point data ``displacement`` (3
components) and ``velocity``, and cell data ``principal_stretches`` (3 components, the signed
stretches of the invertible SVD; 1 in the plane-strain direction in 2D), ``von_mises``, ``J``
(``det F``) and ``region`` (the cell tag). ParaView's "Warp By Vector" on ``displacement``
shows the deformed body; the ``.pvd`` lists the frames with their times (static runs: the load
factor).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ...interrupt import Interrupted, active_flag, raising
from ...io.atomic import EARLIER_RUN, atomic_directory
from ...mesh.vtk import pad3, write_cells, write_collection

__all__ = ["write_solid_outputs", "write_solid_frames"]


def write_solid_frames(directory: str | os.PathLike, result, stop=None) -> list[str]:
    """One VTU per frame in ``directory/frames``; returns their relative names.

    ``stop`` (a :class:`~femkit.interrupt.StopFlag`) is checked before each frame: once set,
    the names of the frames written so far are returned."""
    body = result.problem.body
    ctype = "tetra" if body.dim == 3 else "triangle"
    if body.element == "P2":    # VTK_QUADRATIC_TRIANGLE 22 / VTK_QUADRATIC_TETRA 24
        ctype += "10" if body.dim == 3 else "6"
    cells = [(ctype, np.asarray(body.rest.cells, dtype=np.int64))]
    region = np.asarray(result.problem.mesh.cell_tags, dtype=np.int32)
    names = []
    for k in range(len(result.x)):
        if stop:
            break
        f = result.fields(k)
        s = np.ones((body.rest.n_cells, 3))
        s[:, :body.dim] = f["principal_stretches"]
        name = f"frames/frame_{k:05d}.vtu"
        write_cells(Path(directory) / name, body.rest_positions, cells,
                    point_data={"displacement": pad3(result.x[k] - body.rest_positions),
                                "velocity": pad3(result.v[k]),
                                **({"contact_force": result.contact_forces[k]}
                                   if result.contact_forces else {})},
                    cell_data={"principal_stretches": [s], "von_mises": [f["von_mises"]],
                               "J": [f["J"]], "region": [region]})
        names.append(name)
    return names


def write_solid_outputs(result, directory: str | os.PathLike) -> Path:
    """Every requested output of ``result`` (a SolidResult) into ``directory``, atomically.

    Under a stop request (:func:`femkit.interrupt.active_flag`): when the solve itself was
    stopped, every frame it computed is written and the pictures are skipped; a stop during
    the frames keeps those written so far, a stop during a picture abandons it at once
    (:func:`femkit.interrupt.raising`); either way ``result.output_stop`` names the signal and
    result.json is written with ``interrupted: true``."""
    opts = result.case.spec.output
    final = Path(directory).resolve()
    result.output_dir = final
    files: list[str] = []
    flag = result.case.options.stop   # the run's flag (femkit solve: the active one)
    flag = active_flag() if flag is None else flag
    stop = None if flag else flag   # a stop already answered by the solve: write every frame
    with atomic_directory(final, EARLIER_RUN) as tmp:
        if opts.vtu:
            frames = write_solid_frames(tmp, result, stop=stop)
            write_collection(tmp / "solid.pvd", result.times[:len(frames)], frames)
            files += ["solid.pvd", *frames]
            if len(frames) < len(result.x):
                result.frames_written = len(frames)
        files += _pictures(tmp, result, opts, flag)
        if flag and flag.name != result.stopped:
            result.output_stop = flag.name
        result.write_result_json(tmp, [*files, "result.json"])
    return final


def _pictures(tmp: Path, result, opts, flag) -> list[str]:
    """``deformed.png`` and ``animation.gif`` as asked, in ``tmp``; none once ``flag`` (a
    :class:`~femkit.interrupt.StopFlag` or None) is set: before (the solve was stopped) or
    while one is drawn (abandoned at once)."""
    from .plot import write_solid_gif, write_solid_png

    files: list[str] = []
    wanted = [(opts.png, "deformed.png", write_solid_png), (opts.gif, "animation.gif", write_solid_gif)]
    for on, name, write in wanted:
        if not on or flag:
            continue
        try:
            with raising(f"writing {name}"):
                write(tmp / name, result)
        except Interrupted:
            break
        files.append(name)
    return files
