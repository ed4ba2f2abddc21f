"""The run, result and outputs the time-dependent PDE kinds share (``problem: heat``, ``wave``).

:func:`run_transient` builds the mesh and the system, refuses a step above the critical one
(explicit schemes) before anything is written, marches (:mod:`femkit.dynamics.mol`), computes
the error history against ``exact`` and the energies per frame, and writes (atomically, into
the output directory): ``frames/frame_NNNNN.vtu`` + ``<kind>.pvd`` (a ParaView time series of
``u``, and ``v`` for the wave; P2 on VTK's quadratic cells), ``final.png`` (the last frame),
``animation.gif`` when asked, and ``result.json``. A bad input
found at run time (a time-dependent expression that is not finite at some step, a step above
the critical one) raises before the output directory exists: nothing is written.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..result import RunResult

__all__ = ["TransientResult", "run_transient", "write_transient_outputs", "write_gif"]


@dataclass
class TransientResult(RunResult):
    """A heat or wave run: frames ``(t, u, v)``, the march's facts, errors and energies.

    Kinds subclass it for their summary's first lines (``kind_line``)."""

    case: Any
    mesh: Any
    frames: list
    march: Any
    scheme: Any
    stability: dict
    errors: dict | None
    energies: list
    linear: dict
    timings: dict = field(default_factory=dict)
    files: list = field(default_factory=list)
    output_dir: Any = None
    stopped: str | None = None

    @property
    def converged(self) -> bool:
        return self.march.failure is None and self.stopped is None

    @property
    def interrupted(self) -> str | None:
        return self.stopped

    @property
    def verdict(self) -> str:
        if self.march.failure is not None:
            return "unstable" if "finite" in self.march.failure else "failed"
        return "interrupted" if self.stopped else "converged"

    def facts(self) -> dict:
        spec, m = self.case.spec, self.mesh
        adaptive = None
        if spec.rtol_t is not None:
            adaptive = {"rtol_t": spec.rtol_t, "accepted": self.march.steps,
                        "rejected": self.march.rejected,
                        "steps": [{"dt": float(h), "error_estimate": float(e)}
                                  for h, e in zip(self.march.dts, self.march.errors)]}
        return {
            "mesh": {"dim": m.dim, "n_points": int(m.n_points), "n_cells": int(m.n_cells),
                     "source": spec.mesh.source(), "refine": spec.mesh.refine},
            "element": spec.element, "mass": spec.mass,
            "integrator": self.scheme.describe(),
            "dt": spec.dt, "dt_asked": spec.dt_asked, "t_end": spec.t_end,
            "t_reached": float(self.march.t_reached), "steps": int(self.march.steps),
            "steps_planned": None if adaptive else spec.steps, "adaptive": adaptive,
            "stability": self.stability, "linear_solver": self.linear,
            "frames": len(self.frames), "times": [float(t) for t, _, _ in self.frames],
            "errors": self.errors, "energies": self.energies,
            "converged": self.converged, "interrupted": self.stopped is not None,
            "verdict": self.verdict, "failure": self.march.failure,
            "timings": dict(self.timings), "files": list(self.files),
        }

    def kind_line(self) -> str:
        return f"{self.case.problem:<9} {self.case.name}"

    def summary_lines(self) -> list[str]:
        spec, m, r = self.case.spec, self.mesh, self.march
        lines = [f"{self.kind_line()}: {m.n_points} nodes, {m.n_cells} "
                 f"{'triangles' if m.dim == 2 else 'tetrahedra'}, {spec.element}, {spec.mass} mass",
                 f"method    {self.scheme.name}, " + (
                     f"adaptive dt (rtol_t {spec.rtol_t:g}): {r.steps} steps, {r.rejected} rejected"
                     if spec.rtol_t is not None else f"dt {spec.dt:.4g}, {r.steps} of {spec.steps} steps")
                 + f", t = {r.t_reached:.4g} of {spec.t_end:.4g}"]
        st = self.stability
        if st.get("dt_critical") is not None:
            lines.append(f"stability dt_critical {st['dt_critical']:.4g} (lambda_max "
                         f"{st['lambda_max']:.4g}): dt / dt_critical = {spec.dt / st['dt_critical']:.3f}")
        lin = self.linear
        where = f" on petsc, {lin['ranks']} rank{'s' if lin['ranks'] > 1 else ''}" \
            if lin.get("backend") == "petsc" else ""
        lines.append(f"linear    {lin['method']}{where}: {lin['factorizations']} factorisations, "
                     f"{lin['solves']} solves, {lin['seconds_per_step'] * 1e3:.3g} ms per step")
        if self.errors is not None:
            top, fin = self.errors["max_over_time"], self.errors["final"]

            def num(v):  # None: no norm (H1 without a gradient, an overflowing unstable frame)
                return "none" if v is None else format(v, ".4e")
            lines.append(f"errors    max over time: L2 {num(top['L2'])}, H1 "
                         f"{num(top['H1_semi'])}; at t = {fin['t']:.4g}: L2 {num(fin['L2'])}")
        e0, e1 = self.energies[0], self.energies[-1]
        key = "total" if "total" in e0 else "thermal"
        lines.append(f"energy    {key} {e0[key]:.6g} -> {e1[key]:.6g}")
        lines.append(f"verdict   {self.verdict}" + (f": {r.failure}" if r.failure else ""))
        lines.append(self.timings_line())
        if self.output_dir is not None:
            lines.append(self.output_line())
        return lines


def _linear_facts(system, march) -> dict:
    st = system.stats
    return {"method": system.solver.method, "preconditioner": system.solver.preconditioner,
            "factorizations": int(st["factorizations"]),
            "factor_seconds": float(st["factor_seconds"]), "solves": int(st["solves"]),
            "seconds_per_step": float(march.seconds_per_step),
            "kept_factor": system.solver.method in ("direct", "cholesky"),
            "preconditioner_setups": int(st.get("preconditioner_setups", 0)),
            "iterations": int(st.get("linear_iterations", 0))}


def run_transient(case, capacity: str, registry, *, second_order: bool,
                  output_dir: str | os.PathLike | None = None, quiet: bool = False,
                  write: bool = True, echo: Callable[[str], Any] | None = None,
                  result_type=TransientResult) -> TransientResult:
    """Run a prepared heat (``second_order=False``) or wave case; see the module docstring.

    With ``solver.backend: petsc`` the run is on every rank of ``PETSc.COMM_WORLD`` (one
    process, or ``mpirun -n N``): :mod:`femkit.case.transient.distributed`; rank 0 writes the
    outputs and prints, every rank returns the result."""
    args = (case, capacity, registry, second_order, output_dir, quiet, write, echo, result_type)
    if case.spec.solver.backend != "petsc":
        return _run(*args, None)
    from ...solvers.petsc import require_petsc
    from ...solvers.petsc.failure import abort_on_error

    comm = require_petsc().COMM_WORLD
    with abort_on_error(comm.tompi4py()):
        return _run(*args, comm)


def _run(case, capacity, registry, second_order, output_dir, quiet, write, echo, result_type,
         comm) -> TransientResult:
    from ...dynamics.mol import get_scheme, march, march_adaptive
    from ...interrupt import raising
    from ...io.atomic import EARLIER_RUN, check_output_dir
    from ...progress import Progress
    from ...timing import StageTimer
    from ..poisson.problem import build_mesh
    from .setup import build_system, check_step, frame_errors, initial_values

    spec = case.spec
    root = comm is None or comm.getRank() == 0
    on_root, on_all = _on_root(comm), _on_all(comm)
    if write:
        on_root(check_output_dir, output_dir or spec.output.dir, EARLIER_RUN)
    timer = StageTimer()
    with raising("meshing"), timer("mesh"):
        mesh = build_mesh(case) if comm is None else _broadcast_mesh(case, build_mesh, comm)
    scheme = get_scheme(registry, spec.integrator[0], **dict(spec.integrator[1]))
    with raising("assembly"), timer("assembly"):
        if comm is None:
            system = build_system(case, mesh, capacity)
        else:
            from .distributed import build_distributed_system

            system = build_distributed_system(case, mesh, capacity, comm)
    with timer("stability"):   # distributed: the eigenvalue on the serial matrices, when needed
        serial = system if comm is None or scheme.stability_bound == float("inf") else \
            build_system(case, mesh, capacity)
        stability = on_all(check_step, case, serial, scheme)
    u0 = initial_values(case, mesh, "initial")
    v0 = initial_values(case, mesh, "initial_velocity") if second_order else None
    stop = case.options.stop
    every = max(1, spec.steps // spec.output.frames)
    with timer("steps"):
        if spec.rtol_t is not None:
            run = on_all(march_adaptive, system, scheme, u0, 0.0, spec.t_end, spec.dt,
                         spec.rtol_t, stop=stop)
        else:
            progress = Progress(spec.steps, f"{case.problem} {case.name}", unit="step",
                                quiet=quiet or not root)
            run = on_all(march, system, scheme, u0, 0.0, spec.dt, spec.steps, v0=v0,
                         every=every, stop=stop, progress=progress)
    with timer("errors"):
        errors = frame_errors(case, mesh, run.frames) if run.failure is None and root else None
    energies = [{"t": float(t), **system.energy(u, v)} for t, u, v in run.frames]
    linear = _linear_facts(system, run)
    if comm is not None:
        linear.update(backend="petsc", ranks=comm.getSize())
    result = result_type(case=case, mesh=mesh, frames=run.frames, march=run, scheme=scheme,
                         stability=stability, errors=errors, energies=energies,
                         linear=linear, timings=timer.times,
                         stopped=stop.name if run.interrupted else None)
    if write:
        with timer("output"):
            final = on_root(write_transient_outputs, result, output_dir or spec.output.dir)
        result.output_dir = final
    if not quiet and root:
        for line in result.summary_lines():
            (echo or print)(line)
    return result


def _on_root(comm):
    """``fn(*args)`` on rank 0, its result broadcast (errors raised on every rank); serial:
    a plain call."""
    if comm is None:
        return lambda fn, *args: fn(*args)
    from ...solvers.petsc.failure import from_root

    return lambda fn, *args: from_root(comm.tompi4py(), fn, *args)


def _on_all(comm):
    """``fn(*args, **kwargs)`` on every rank, an error raised on all of them (a step of
    replicated data fails alike everywhere: each rank exits 2 by itself, rank 0 says it,
    no ``MPI_Abort``); serial: a plain call."""
    if comm is None:
        return lambda fn, *args, **kwargs: fn(*args, **kwargs)
    from ...solvers.petsc.failure import collective

    return lambda fn, *args, **kwargs: collective(comm.tompi4py(), fn, *args, **kwargs)


def _broadcast_mesh(case, build_mesh, comm):
    from ...fem.distributed.poisson import broadcast_mesh

    return broadcast_mesh(lambda: build_mesh(case), comm)


def write_transient_outputs(result: TransientResult, directory: str | os.PathLike) -> Path:
    """``frames/*.vtu`` + ``<problem>.pvd``, ``final.png`` and ``result.json`` into
    ``directory``, atomically (:func:`femkit.io.atomic.atomic_directory`)."""
    from ...io.atomic import EARLIER_RUN, atomic_directory
    from ...mesh.vtk import VtuFrames, write_collection

    opts = result.case.spec.output
    mesh = result.mesh
    final = Path(directory).resolve()
    files: list[str] = []
    with atomic_directory(final, EARLIER_RUN) as tmp:
        if opts.vtu:
            (tmp / "frames").mkdir()
            from ...fem.dofs import dof_map

            dofs = dof_map(mesh, result.case.spec.element)
            quadratic = dofs.element.degree == 2   # VTK's quadratic cells: the dofs' own order
            kind = ("triangle6" if mesh.dim == 2 else "tetra10") if quadratic else \
                ("triangle" if mesh.dim == 2 else "tetra")
            series = VtuFrames([(kind, np.asarray(dofs.cells, dtype=np.int64))])
            points = dofs.points(mesh)
            names = []
            for k, (t, u, v) in enumerate(result.frames):
                name = f"frames/frame_{k:05d}.vtu"
                data = {"u": u} if v is None else {"u": u, "v": v}
                series.write(tmp / name, points, point_data=data)
                names.append(name)
            pvd = f"{result.case.problem}.pvd"
            write_collection(tmp / pvd, [t for t, _, _ in result.frames], names)
            files += [pvd, *names]
        if opts.png and result.frames:
            from ..poisson.output import write_plot

            t, u, _ = result.frames[-1]
            write_plot(tmp / "final.png", mesh, u[:mesh.n_points],   # the vertex values
                       f"{result.case.name}: u at t = {t:.4g}")
            files.append("final.png")
        if opts.gif and result.frames:
            write_gif(tmp / "animation.gif", result)
            files.append("animation.gif")
        result.output_dir = final
        result.write_result_json(tmp, [*files, "result.json"])
    return final


def write_gif(path, result, *, max_frames: int = 40, dpi: float = 80) -> Path:
    """Animated GIF of at most ``max_frames`` evenly spaced frames of ``u`` (the vertex values;
    on tetrahedra the section at mid-height), one fixed colour scale over the frames shown."""
    from matplotlib.tri import Triangulation

    from ...io.figures import new_figure
    from ..pictures import gif_frame_times, gif_frames, rgb_image, save_gif

    mesh = result.mesh
    picks = gif_frames(len(result.frames), max_frames)
    values = [result.frames[int(k)][1][:mesh.n_points] for k in picks]
    if mesh.dim == 3:
        from ..poisson.section import plane_section

        zs = mesh.points[:, 2]
        cut = plane_section(mesh, 0.5 * (zs.min() + zs.max()))
        tri = Triangulation(cut.points[:, 0], cut.points[:, 1], cut.triangles)
        values = [cut.interpolate(u) for u in values]
    else:
        tri = Triangulation(mesh.points[:, 0], mesh.points[:, 1], mesh.triangles)
    lo = min(float(u.min()) for u in values)
    hi = max(float(u.max()) for u in values)
    hi = hi if hi > lo else lo + 1.0
    images = []
    for k, u in zip(picks, values):
        fig = new_figure(5.5, 4.5, dpi=dpi)
        ax = fig.add_subplot()
        art = ax.tripcolor(tri, u, shading="gouraud", cmap="viridis", vmin=lo, vmax=hi)
        fig.colorbar(art, ax=ax, label="u")
        ax.set_aspect("equal")
        ax.set_title(f"{result.case.name}: t = {result.frames[int(k)][0]:.4g}", fontsize=9)
        images.append(rgb_image(fig).quantize(colors=128))
    ms = [int(round(1000 * d)) for d in gif_frame_times([f[0] for f in result.frames], picks)]
    return save_gif(path, images, ms)
