"""Outputs of a Poisson run: ``result.json``, the solution as ``.vtu`` / ``.xdmf``, a PNG plot.

Every file is written atomically (see :mod:`femkit.io.atomic`). The keys of ``result.json``
are documented in docs/case-files.md ("Outputs").
"""

from __future__ import annotations

import contextlib
import os
import time
from pathlib import Path

import numpy as np

from ...errors import InputError, with_prefix
from ...io.figures import new_figure, save_figure
from ...mesh.vtk import Later

__all__ = ["write_solution", "write_plot", "write_outputs", "output_location",
           "SolutionFile", "solution_file", "RESULT_KEYS"]

#: Top-level keys of result.json.
RESULT_KEYS = ("case", "problem", "case_file", "femkit_version", "mesh", "dofs", "nnz",
               "solver", "converged", "errors", "error_estimate", "effectivity", "adaptive",
               "timings", "wall", "expressions", "files", "backend", "parallel")


def write_solution(path: str | os.PathLike, mesh, u: np.ndarray,
                   kappa: np.ndarray | float | None = None, extra_point_data: dict | None = None,
                   compression: str | None = None, element: str = "P1", eta=None) -> Path:
    """Write the mesh with point data ``u`` and cell data ``kappa``, ``tag`` and, when given,
    ``eta`` (vtu/xdmf by extension).

    ``eta``: the error estimator's indicator of each cell (``(n_cells,)``, the run's
    ``result.indicators``), or a :class:`~femkit.mesh.vtk.Later` whose values are handed over
    while the file is written (:class:`SolutionFile`).

    ``element="P2"``: quadratic cells (VTK_QUADRATIC_TRIANGLE 22 / VTK_QUADRATIC_TETRA 24, meshio's
    ``triangle6`` / ``tetra10``) whose nodes are the mesh's points followed by the edge midpoints,
    ``u`` given on every one of them (:func:`femkit.fem.dofs.dof_map`'s numbering); ``.vtu`` only.
    Not atomic by itself (meshio may write sibling files); use it inside
    :func:`femkit.io.atomic.atomic_directory`.
    """
    from ...mesh import write_mesh

    if element != "P1":
        return _write_quadratic(Path(path), mesh, u, kappa, compression, element, eta)

    point_data = {"u": np.asarray(u, dtype=np.float64)}
    point_data.update(extra_point_data or {})
    cell_data = {"tag": np.asarray(mesh.cell_tags, dtype=np.int32)}
    if kappa is not None:  # a constant coefficient is one number until here
        kappa = np.asarray(kappa, dtype=np.float64)
        # a constant: a broadcast view, written a block at a time (no array of m copies)
        cell_data["kappa"] = np.broadcast_to(kappa, (mesh.n_cells,)) if kappa.ndim == 0 else kappa
    if eta is not None:
        cell_data["eta"] = eta
    # Written in place: sibling files (XDMF's .h5, a tag-name sidecar) are named after the
    # file, so a temporary name would orphan them. Callers write into an atomic directory.
    target = Path(path)
    write_mesh(target, mesh, point_data=point_data, cell_data=cell_data, compression=compression)
    return target


def _write_quadratic(target: Path, mesh, u, kappa, compression, element: str,
                     eta=None) -> Path:
    """:func:`write_solution` of a P2 field: quadratic cells, ``u`` at every node."""
    from ...fem.dofs import dof_map
    from ...mesh.vtk import write_cells

    dofs = dof_map(mesh, element)
    kind = "triangle6" if mesh.dim == 2 else "tetra10"
    cell_data = {"tag": [np.asarray(mesh.cell_tags, dtype=np.int32)]}
    if kappa is not None:
        kappa = np.asarray(kappa, dtype=np.float64)
        cell_data["kappa"] = [np.full(mesh.n_cells, float(kappa)) if kappa.ndim == 0 else kappa]
    if eta is not None:
        cell_data["eta"] = [eta]
    write_cells(target, dofs.points(mesh), [(kind, dofs.cells)],
                point_data={"u": np.asarray(u, dtype=np.float64)}, cell_data=cell_data,
                **({} if compression is None else {"compression": compression}))
    return target


def plot_triangulation(mesh, u: np.ndarray):
    """``(points, triangles, values, parent)`` to draw a 2D field: the mesh itself for a P1
    ``u`` (one value per node), for a P2 ``u`` each triangle split into four at its edge
    midpoints (the P2 nodal values on the sub-triangles; ``parent`` maps them to their cell)."""
    if len(u) == mesh.n_points:
        return mesh.points, mesh.triangles, u, np.arange(mesh.n_cells)
    from ...fem.dofs import dof_map

    dofs = dof_map(mesh, "P2")
    c = dofs.cells                                            # v0 v1 v2 e01 e12 e02
    sub = np.concatenate([c[:, [0, 3, 5]], c[:, [3, 1, 4]], c[:, [5, 4, 2]], c[:, [3, 4, 5]]])
    return dofs.points(mesh), sub, u, np.tile(np.arange(mesh.n_cells), 4)


def write_plot(path: str | os.PathLike, mesh, u: np.ndarray, title: str = "",
               indicators: np.ndarray | None = None, estimator: str = "") -> Path:
    """Save a PNG of ``u`` with a colour bar (matplotlib, Agg backend); with ``indicators`` a second
    panel shows the element error indicators ``eta_T`` on a logarithmic colour scale.

    On a tetrahedral mesh both panels show the section by the plane ``z`` = the middle of the
    mesh's z range (:func:`~femkit.case.poisson.section.plane_section`: the P1 field on that
    plane exactly, each section triangle coloured by its tetrahedron's indicator)."""
    from matplotlib.colors import LogNorm
    from matplotlib.tri import Triangulation

    u = np.asarray(u, dtype=np.float64)
    total = None if indicators is None else float(np.sqrt(np.sum(np.asarray(indicators) ** 2)))
    if mesh.dim == 3:
        u = u[:mesh.n_points]  # a P2 field: its vertex values (the section interpolates linearly)
        from .section import plane_section

        zs = mesh.points[:, 2]
        cut = plane_section(mesh, 0.5 * (zs.min() + zs.max()))
        tri = Triangulation(cut.points[:, 0], cut.points[:, 1], cut.triangles)
        u = cut.interpolate(u)
        if indicators is not None:
            indicators = np.asarray(indicators)[cut.cells]
        title = f"{title}\nsection z = {cut.z:.4g}" if title else f"section z = {cut.z:.4g}"
    else:
        pts, triangles, u, parent = plot_triangulation(mesh, u)
        tri = Triangulation(pts[:, 0], pts[:, 1], triangles)
        if indicators is not None:
            indicators = np.asarray(indicators)[parent]
    panels = 1 if indicators is None else 2
    fig = new_figure(6 * panels, 5, dpi=120)
    ax = fig.add_subplot(1, panels, 1)
    if mesh.dim == 3:  # thin section triangles leave seams in Gouraud shading: fill contours
        art = ax.tricontourf(tri, u, levels=24, cmap="viridis")
    else:
        art = ax.tripcolor(tri, u, shading="gouraud", cmap="viridis")
    fig.colorbar(art, ax=ax, label="u")
    ax.set_title(title, fontsize=9)
    axes = [ax]
    if indicators is not None:
        eta = np.asarray(indicators, dtype=np.float64)
        pos = eta[eta > 0]
        lo = pos.min() if pos.size else 1e-300
        hi = max(eta.max(), lo * 10)
        ax2 = fig.add_subplot(1, panels, 2)
        art2 = ax2.tripcolor(tri, facecolors=np.maximum(eta, lo), cmap="magma",
                             norm=LogNorm(vmin=max(lo, hi * 1e-8), vmax=hi))
        fig.colorbar(art2, ax=ax2, label="error indicator eta_T (log scale)")
        ax2.set_title(f"{estimator} indicators: estimate {total:.3e}", fontsize=9)
        axes.append(ax2)
    from matplotlib.ticker import MaxNLocator

    for a in axes:
        a.set_aspect("equal")
        a.set_xlabel("x")
        a.set_ylabel("y")
        a.xaxis.set_major_locator(MaxNLocator(5))  # two panels side by side: labels must not touch
        a.yaxis.set_major_locator(MaxNLocator(6))
    fig.tight_layout()
    return save_figure(fig, path)


def output_location(directory: str | os.PathLike) -> Path:
    """The resolved output directory, checked before the run (:func:`check_output_dir`).

    Raises
    ------
    InputError
        (prefixed ``output.dir``) ``directory`` is a file, lies below a file, or is a
        non-empty directory that is not an earlier run (no ``result.json``): replacing it
        would delete the user's files.
    """
    from ...io.atomic import EARLIER_RUN, check_output_dir

    try:
        return check_output_dir(directory, EARLIER_RUN)
    except InputError as exc:
        raise with_prefix(exc, "output.dir") from None


class SolutionFile:
    """``solution.vtu`` written by a writer thread while the run goes on (the errors and the
    estimate need neither the file nor anything it is made of, and the mesh is immutable).

    The file (and its sidecar of tag names) is written into a temporary directory beside the
    output directory (the prefix of :func:`~femkit.io.atomic.atomic_directory`'s) and moved
    into the run's temporary directory by :func:`write_outputs`, which waits for it there: the
    output directory still appears whole or not at all. :meth:`discard` (the run failed or was
    stopped before its outputs; leaving the ``with`` block) waits for the thread and removes
    what was not moved. An error of the writer is raised by :meth:`move_into` (a
    :class:`~femkit.errors.FemkitError`).

    ``u`` and ``kappa`` must not be modified until then (the run hands over its final arrays).
    On one core the write costs what it cost in the output stage; with two, the output stage
    only waits for what is left of it. The estimator's indicators (cell data ``eta``) come
    last: the file declares them at once and the writer fills their bytes when
    :meth:`move_into` hands them over (:class:`~femkit.mesh.vtk.Later`).
    """

    NAME = "solution.vtu"

    def __init__(self, directory: Path, mesh, u: np.ndarray, kappa, compression: str | None,
                 element: str = "P1"):
        import tempfile

        from ...io.background import BackgroundWriter

        directory.parent.mkdir(parents=True, exist_ok=True)
        self.staging: Path | None = Path(tempfile.mkdtemp(prefix=f"{directory.name}.tmp-",
                                                          dir=directory.parent))
        self.eta = Later(mesh.n_cells)
        self._writer = BackgroundWriter(depth=1, name="femkit solution writer")
        self._writer.submit(write_solution, self.staging / self.NAME, mesh, u, kappa, None,
                            compression, element, self.eta)

    def move_into(self, directory: Path, eta: np.ndarray | None = None) -> None:
        """Hand over the indicators ``eta`` (NaN when the run has none), wait for the file,
        then move it and its sidecars into ``directory`` (renames)."""
        self.eta.set(np.full(self.eta.shape, np.nan) if eta is None else eta)
        self._writer.close()
        for path in sorted(self.staging.iterdir()):
            os.replace(path, directory / path.name)
        self.discard()

    def __enter__(self) -> "SolutionFile":
        return self

    def __exit__(self, *exc) -> None:
        self.discard()

    def discard(self) -> None:
        """Wait for the writer (bounded) and remove what was not moved."""
        self.eta.abandon()  # a writer waiting for the indicators stops at once
        self._writer.cancel()
        if self.staging is not None:
            import shutil

            shutil.rmtree(self.staging, ignore_errors=True)
            self.staging = None


def solution_file(case, target: Path | None, mesh, u: np.ndarray, kappa):
    """A :class:`SolutionFile` being written when the case asks for ``solution.vtu`` and the
    run writes its outputs (``target``), else a context that holds ``None``."""
    if target is None or not case.spec.output.vtu:
        return contextlib.nullcontext(None)
    return SolutionFile(target, mesh, u, kappa, case.spec.output.compression, case.spec.element)


def write_outputs(result, directory: str | os.PathLike, *, write_pieces=None,
                  solution: SolutionFile | None = None) -> Path:
    """Write result.json and the requested solution files into ``directory`` (atomically).

    ``directory`` is replaced as a whole, so it must be new, empty or an earlier run
    (:func:`output_location`). ``write_pieces(tmp)`` (a distributed run whose solution is
    too large to gather) writes ``solution.pvtu`` and its pieces instead of ``solution.vtu``;
    the xdmf and png outputs need the gathered solution (``result.u``) and are left out
    without it (listed in ``result.parallel["not_written"]``). ``solution``: ``solution.vtu``
    already being written (:class:`SolutionFile`), moved in here.
    """
    from ...io.atomic import EARLIER_RUN, atomic_directory

    opts = result.case.spec.output
    final = output_location(directory)
    result.output_dir = final
    t0 = time.perf_counter()
    with atomic_directory(final, EARLIER_RUN) as tmp:
        if opts.vtu and write_pieces is not None:
            write_pieces(tmp)
        elif opts.vtu and solution is not None:
            solution.move_into(tmp, result.indicators)
        elif opts.vtu:
            write_solution(tmp / "solution.vtu", result.mesh, result.u, result.kappa,
                           compression=opts.compression, element=result.case.spec.element,
                           eta=result.indicators)
        if result.u is None:
            result.parallel["not_written"] = [f"solution.{e}" for e, k in
                                              (("xdmf", "xdmf"), ("png", "plot")) if getattr(opts, k)]
        elif opts.xdmf:
            write_solution(tmp / "solution.xdmf", result.mesh, result.u, result.kappa,
                           eta=result.indicators)
        if opts.plot and result.u is not None:
            from ...mesh.mesh import CELLS_NAME

            title = (f"{result.case.name}: {result.mesh.n_cells} {CELLS_NAME[result.mesh.dim]}, "
                     f"h_max = {result.quality.get('h_max', float('nan')):.3g}")
            est = result.error_estimate or {}
            write_plot(tmp / "solution.png", result.mesh, result.u, title,
                       indicators=result.indicators, estimator=est.get("estimator", ""))
        result.timings["output"] = time.perf_counter() - t0  # up to result.json itself
        result.write_result_json(tmp, sorted({p.name for p in tmp.iterdir()} | {"result.json"}))
    result.timings["output"] = time.perf_counter() - t0
    return final
