"""Run a ``problem: mass_spring`` scene end to end: system, forces, integrator, outputs.

``femkit solve SCENE.yaml`` dispatches here through :data:`femkit.kinds.KINDS`:
:func:`prepare_scene` checks everything at load time (integrator, linear solver and
preconditioner names against their registries, integrator options, mesh geometry and file,
expressions, output cadence), so bad input fails before anything is computed or written;
:func:`run_scene` builds the system with *only the declared forces*, runs
:func:`femkit.dynamics.simulate.simulate` and writes the outputs atomically
(:mod:`femkit.case.scene.output`): the frames by a writer thread while the simulation runs
(:class:`~femkit.case.scene.output.FrameStream`, off the run's critical path), the other files
after it, all into the output directory's temporary place, moved into place at the end.

Stability: an :class:`~femkit.errors.InstabilityError` does not escape :func:`run_scene`. The
trajectory up to the last good step is written, ``result.json`` says ``"verdict":
"unstable"`` with the error's facts, and :attr:`SceneResult.converged` is false, so
``femkit solve`` exits with code 1 ("ran, but did not reach its goal"). A step that fails
(:class:`~femkit.errors.SolverError`: Newton, a linear solve, a moving obstacle that cannot get
to its place) is kept the same way, ``"verdict": "newton_failed"`` or ``"solver_failed"`` with
its step and message, as a solid's run keeps it.

Each stage is a public function (:func:`build_system`, :func:`build_integrator`,
:func:`build_context`, :func:`output_every`), so a Python user can reuse one of them::

    case = femkit.load_case("cases/scenes/rope_pendulum.yaml", t_end=0.5)
    system, triangles = build_system(case)
    result = run_scene(case, write=False, quiet=True)
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import os
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ...dynamics.integrators import StepContext
from ...dynamics.integrators.base import check_matrix_free
from ...dynamics.simulate import StabilityWarning, simulate
from ...dynamics.stability import estimate_omega_max
from ...errors import (
    CaseFileError,
    ExpressionError,
    EquilibriumError,
    InputError,
    InstabilityError,
    SolverError,
    UnknownNameError,
    with_prefix,
)
from ...io.atomic import EARLIER_RUN, atomic_directory, check_output_dir
from ...kinds import KINDS
from ...progress import Progress
from ...timing import StageTimer
from .cost import check_scene_fits
from ..expressions import compile_expression
from ..frozen import freeze
from ..contact import ContactRecorder, build_contact, check_contact_integrator, resolve_obstacle_files
from ..load import Case
from ..name_checks import check_geometry_spec, resolve_file
from ..result import RunResult
from ..specs import IntegratorSpec, limits_spec, solver_spec
from ..timeline import time_value
from .forces import FORCES
from .output import FrameStream, write_scene_outputs
from .spec import OutputSpec, SceneSpec, StabilitySpec, record_every
from .systems import SYSTEMS, system_size

__all__ = ["prepare_scene", "run_scene", "build_system", "build_integrator", "build_context",
           "output_every", "n_steps", "SceneResult", "state_checksum", "FORCES", "SYSTEMS"]


# ----------------------------------------------------------------------------- prepare

def _normalise_forces(spec) -> list[dict]:
    """Forces as a list of ``{type: ..., params...}`` (mapping form and gravity shorthand too)."""
    if isinstance(spec, dict):
        out = []
        for name, params in spec.items():
            if name == "gravity" and not isinstance(params, dict):
                params = {"g": params}
            out.append({"type": name, **{k: v for k, v in params.items() if k != "type"}})
        return out
    return [dict(f) for f in spec]


def prepare_scene(case: Case) -> None:
    """Check a validated scene against the registries and build its :class:`SceneSpec`
    (``case.spec``; load time, nothing runs).

    Normalises ``integrator`` to an :class:`IntegratorSpec` and ``forces`` to a list of
    ``{type, ...}``, evaluates ``dt``/``t_end`` expressions, compiles ``system.velocity``
    expressions into ``case.functions``, builds the linear solver spec (``case.solver``), makes
    ``system.file`` and ``output.dir`` absolute, and computes the output cadence once.

    Raises
    ------
    UnknownNameError
        Unknown integrator, linear solver, preconditioner or mesh geometry (valid names listed).
    CaseFileError
        Bad integrator options, mesh file not found, conflicting keys.
    ExpressionError
        Unsafe or malformed expression.
    """
    d = case.data
    if d.get("name"):
        case.name = d["name"]

    # integrator: name and options checked by building it once
    try:
        integ = IntegratorSpec.from_mapping(d["integrator"], "integrator")
    except UnknownNameError:
        raise
    except InputError as exc:
        raise CaseFileError(str(exc)) from None

    contact = dict(d["contact"]) if d.get("contact") is not None else None
    if contact is not None:
        check_contact_integrator(integ.method)
        contact["obstacles"] = [dict(o) for o in contact.get("obstacles") or []]
        resolve_obstacle_files(contact, case.base_dir)

    # linear solver
    default = KINDS.get(case.problem, "problem").default_solver
    ls_spec = solver_spec(d["linear_solver"], "linear_solver", default_method=default)
    case.options = dataclasses.replace(case.options, limits=limits_spec(d.get("limits")))
    if integ.options.get("matrix_free"):  # caught at load time, before anything runs
        try:
            check_matrix_free(integ.method, StepContext(ls_spec))
        except InputError as exc:
            raise CaseFileError(f"linear_solver: {exc}") from None

    # times
    dt = time_value(case, "dt")
    t_end = time_value(case, "t_end")
    steps = int(round(t_end / dt))
    if steps < 1:
        raise CaseFileError(f"t_end: {t_end:g} is shorter than one step dt = {dt:g}")

    # system
    system = dict(d["system"])
    if system["type"] == "mesh":
        _prepare_mesh(system, case.base_dir)
    forces = _normalise_forces(d["forces"])
    damping_forces = [n for n in FORCES.names() if FORCES.get(n).spring_damping]
    if "damping" in system and any(f["type"] in damping_forces for f in forces):
        raise CaseFileError("system.damping: give the dashpot coefficient either as "
                            "system.damping or as a 'dashpot' force, not both")
    kinds = [f["type"] for f in forces]
    for kind in FORCES.names():
        if kinds.count(kind) > 1 and not FORCES.get(kind).repeatable:
            raise CaseFileError(f"forces: {kind!r} is declared {kinds.count(kind)} times "
                                f"(only {_repeatable()} may repeat)")
    for i, comp in enumerate(system.get("velocity") or []):
        key = f"system.velocity[{i}]"
        try:
            case.functions[key] = compile_expression(comp, ("x", "y", "z"),
                                                     d.get("constants") or {})
        except ExpressionError as exc:
            raise ExpressionError(f"{key}: {exc}") from None

    out = d["output"]
    if "every" in out and "interval" in out:
        raise CaseFileError("output: give 'every' (steps) or 'interval' (seconds), not both")
    directory = str((case.base_dir / out.get("dir", os.path.join("runs", case.name))).resolve())
    # the file's data, normalised once (what result.json echoes and cost models read);
    # frozen by the loader right after this
    d.update(integrator={"method": integ.method, "options": dict(integ.options)},
             linear_solver=ls_spec.to_dict(), dt=dt, t_end=t_end, system=system, forces=forces)
    out["dir"] = directory
    st = d["stability"]
    case.spec = SceneSpec(
        system=freeze(system), forces=tuple(freeze(f) for f in forces), integrator=integ, solver=ls_spec, dt=dt,
        t_end=t_end, steps=steps,
        output=OutputSpec(directory, record_every(steps, dt, out), bool(out["vtu"]),
                          bool(out["xdmf"]), bool(out["energy_csv"]), bool(out["png"]),
                          bool(out["gif"])),
        stability=StabilitySpec(bool(st["check"]), float(st["energy_growth_limit"]),
                                int(st["check_every"])),
        contact=None if contact is None else freeze(contact))


def _repeatable() -> str:
    return ", ".join(repr(n) for n in FORCES.names() if FORCES.get(n).repeatable) or "none"


def _prepare_mesh(system: dict, base: Path) -> None:
    if "file" in system:
        resolve_file(system, "system", base)
    else:
        check_geometry_spec(system, "system")


# ----------------------------------------------------------------------------- build

def _forces(case: Case) -> tuple[list, float | None]:
    """Force objects for the declared forces, and the dashpot coefficient (None: no dashpot)."""
    objs, dashpot = [], None
    for f in case.spec.forces:
        ftype = FORCES.get(f["type"])  # the schema admits only registered types
        if ftype.spring_damping:
            dashpot = float(f[ftype.spring_damping])
        else:
            objs.append(ftype.build(f))
    return objs, dashpot


def build_system(case: Case):
    """The :class:`MassSpringSystem` of the scene and its triangles (``None`` for rope/spring).

    Only the declared forces are attached; the dashpot is present only when declared
    (``system.damping`` or a ``dashpot`` force).
    """
    s = dict(case.spec.system)
    kind = s.pop("type")
    s.pop("velocity", None)
    forces, dashpot = _forces(case)
    damping = s.pop("damping", dashpot if dashpot is not None else 0.0)
    origin = s.pop("origin", None)
    builder = SYSTEMS.get(kind).build  # the schema admits only registered types
    try:
        system, triangles, *notes = builder(s, origin, dict(forces=forces, damping=damping))
    except CaseFileError:
        raise
    except InputError as exc:
        raise with_prefix(exc, "system") from None
    known = case.notes
    known.extend(n for n in (notes[0] if notes else ()) if n not in known)
    if case.spec.contact is not None:
        attach_contact(case.spec.contact, system, triangles)
    vel = [case.functions[f"system.velocity[{i}]"]
           for i in range(len(case.spec.system.get("velocity") or []))]
    if vel:
        if len(vel) != system.dim:
            raise CaseFileError(f"system.velocity: needs {system.dim} components for a "
                                f"{system.dim}D system, got {len(vel)}")
        x = system.x0
        cols = [x[:, 0], x[:, 1], x[:, 2] if system.dim == 3 else np.zeros(system.n)]
        v0 = np.stack([np.broadcast_to(f(*cols), (system.n,)) for f in vel], axis=1)
        v0[system.pinned] = 0.0
        system.v0 = np.ascontiguousarray(v0, dtype=float)
    return system, triangles


def attach_contact(contact, system, triangles) -> None:
    """Attach the barrier contact of a ``contact:`` mapping to ``system``, on its triangles (a
    rope's or a spring mesh's springs without them); raises InputError (one line naming a pair
    of elements) when the initial state intersects."""
    cells = triangles if triangles is not None and len(triangles) else system.springs
    if system.dim == 3 and np.asarray(cells).shape[1] == 2:
        raise CaseFileError("contact: a 3-D system needs triangles for barrier contact "
                            "(cloth or mesh systems)")
    try:
        system.attach(build_contact(contact, system.x0, cells))
        system.forces[-1].model.check_intersection_free(system.x0)
    except CaseFileError:
        raise
    except InputError as exc:
        raise CaseFileError(str(exc)) from None


def contact_force(system):
    """The system's barrier contact force, or None."""
    return next((f for f in system.forces if getattr(f, "requires_bounded_steps", False)), None)


def build_integrator(case: Case):
    """The integrator object named by ``integrator.method`` with its ``options``."""
    return case.spec.integrator.build()


def build_context(case: Case):
    """A :class:`~femkit.dynamics.integrators.StepContext` holding the ``linear_solver`` spec."""
    return StepContext(case.spec.solver)


def n_steps(case: Case) -> int:
    """Number of steps ``round(t_end / dt)``."""
    return case.spec.steps


def output_every(case: Case) -> int:
    """Output cadence in steps: ``every``, else ``round(interval / dt)``, else enough steps
    for about ``frames`` frames (``ceil(steps / frames)``)."""
    return case.spec.output.every


def state_checksum(x: np.ndarray) -> str:
    """SHA-256 of the positions rounded to 9 decimals (little-endian float64, ``-0`` folded to 0).

    Equal checksums mean equal states to 1e-9 (up to a value straddling a rounding boundary).

    >>> state_checksum(np.array([[1e-12, -1e-12]])) == state_checksum(np.zeros((1, 2)))
    True
    """
    r = np.round(np.asarray(x, dtype=float), 9) + 0.0
    return hashlib.sha256(np.ascontiguousarray(r, dtype="<f8").tobytes()).hexdigest()


# ----------------------------------------------------------------------------- result

def _declared(case: Case, system) -> list[str]:
    """Declared force types, with ``dashpot`` when the springs carry a damping coefficient."""
    kinds = [f["type"] for f in case.spec.forces]
    if "dashpot" not in kinds and np.any(np.asarray(system.damping) != 0):
        kinds.append("dashpot")
    if case.spec.contact is not None:
        kinds.append("barrier contact")
    return kinds


@dataclass
class SceneResult(RunResult):
    """What a scene run produced: the trajectory in memory and the facts of ``result.json``
    (the scene kind's :class:`~femkit.case.result.RunResult`)."""

    case: Case
    system: Any
    integrator: Any
    trajectory: Any
    triangles: np.ndarray | None
    instability: InstabilityError | None
    every: int
    wall_time: float
    timings: dict
    omega_max: float | None = None
    warnings: list = field(default_factory=list)
    contact: Any = None                 # ContactRecorder of a run with barrier contact
    output_dir: Path | None = None
    files: list = field(default_factory=list)
    output_stop: str | None = None      # signal that stopped the frame writing, if one did
    frames_written: int | None = None   # frames written before it (None: all)
    failed_step: SolverError | None = None  # the step that failed (Newton, a linear solve)

    @property
    def converged(self) -> bool:
        """False when the run stopped on an instability or a failed step (``femkit solve`` then
        exits 1)."""
        return self.instability is None and self.failed_step is None

    @property
    def interrupted(self) -> str | None:
        """The signal that stopped the run or its frame writing early (``"SIGTERM"`` ...),
        else None."""
        if self.output_stop is not None:
            return self.output_stop
        if not getattr(self.trajectory, "interrupted", False):
            return None
        stop = self.case.options.stop
        return getattr(stop, "name", None) or "a stop request"

    @property
    def verdict(self) -> str:
        """``unstable`` when the run stopped on an instability, ``newton_failed`` /
        ``solver_failed`` on a failed step, else the base verdict."""
        if self.instability is not None:
            return "unstable"
        if self.failed_step is not None:
            return "newton_failed" if isinstance(self.failed_step, EquilibriumError) \
                else "solver_failed"
        return super().verdict

    @property
    def failure(self) -> str | None:
        """One-line reason of the failure (None when stable)."""
        e = self.instability if self.instability is not None else self.failed_step
        return None if e is None else " ".join(str(e).split())

    def stability(self) -> dict:
        tr = self.trajectory
        dt = self.case.spec.dt
        om = tr.omega_max if tr.omega_max is not None else self.omega_max
        exceeds = tr.dt_exceeds_critical
        if exceeds is None and self.integrator.implicit:
            exceeds = False  # unconditionally stable: no critical step to exceed
        out = {"verdict": "stable" if self.instability is None else "unstable",
               "dt_exceeds_critical": exceeds,
               "omega_max": om, "dt_crit": tr.dt_crit,
               "h_omega_max": None if om is None else dt * om,
               "stability_bound": self.integrator.describe()["stability_bound"],
               "energy_growth_limit": self.case.spec.stability.energy_growth_limit}
        e = self.instability
        if e is not None:
            out.update(method=e.method, step=int(e.step), time=float(e.time),
                       energy_ratio=float(e.energy_ratio), dt=float(e.dt), reason=e.reason,
                       dt_crit=e.dt_crit, message=self.failure)
        if self.failed_step is not None:
            out.update(verdict=self.verdict, step=getattr(self.failed_step, "step", None),
                       message=self.failure)
        return out

    def facts(self) -> dict:
        """The scene keys of ``result.json`` (documented in docs/scenes.md)."""
        tr = self.trajectory
        s = self.system
        x_final = tr.x[-1]
        e = tr.energies["total"]
        stats = tr.summary()["stats"]
        desc = self.integrator.describe()
        return {
            "system": {"type": self.case.spec.system["type"], "particles": int(s.n),
                       "springs": int(s.n_springs), "dim": int(s.dim), "dofs": int(s.ndof),
                       "pinned": int(np.count_nonzero(s.pinned)),
                       "triangles": 0 if self.triangles is None else int(len(self.triangles)),
                       "forces": _declared(self.case, s)},
            "integrator": {k: desc[k] for k in ("name", "order", "implicit", "symplectic",
                                                "stability_bound", "options")},
            "linear_solver": {**self.case.spec.solver.to_dict(),
                              "used": bool(desc["implicit"]),
                              "factorizations": int(stats.get("factorizations", 0)),
                              "linear_solves": int(stats.get("linear_solves", 0)),
                              "iterations": int(stats.get("linear_iterations", 0)),
                              "stats": stats},
            "dt": self.case.spec.dt,
            "t_end": self.case.spec.t_end,
            "steps": int(tr.steps),
            "steps_planned": n_steps(self.case),
            "interrupted": self.interrupted is not None,
            "t_reached": float(tr.times[-1]),
            "frames": int(len(tr.times) if self.frames_written is None else self.frames_written),
            "output_every": int(self.every),
            "wall_time": float(self.wall_time),
            "step_time": float(tr.wall_time / tr.steps) if tr.steps else None,
            "energy": {"initial": float(e[0]), "final": float(e[-1]),
                       "scale": float(tr.energy_scale), "drift": float(tr.energy_drift),
                       "max_deviation": float(np.max(np.abs(e - e[0])) / tr.energy_scale)},
            "final_state": {"checksum": state_checksum(x_final),
                            "sum_x": float(x_final.sum()),
                            "sum_abs_x": float(np.abs(x_final).sum()),
                            "sum_v": float(tr.v[-1].sum())},
            "momentum_final": tr.momentum[-1],
            "stability": self.stability(),
            "converged": self.converged,
            "warnings": list(self.warnings),
            "timings": dict(self.timings),
            "files": list(self.files),
            **({} if self.contact is None else {"contact": self.contact.facts()}),
        }

    def summary_lines(self) -> list[str]:
        """Short human summary (what ``femkit solve`` prints)."""
        d = self.to_dict()
        sy, it, st = d["system"], d["integrator"], d["stability"]
        kind = "implicit" if it["implicit"] else "explicit"
        kind += ", symplectic" if it["symplectic"] else ""
        lines = [
            f"scene     {self.case.name} (problem {self.case.problem})",
            f"system    {sy['type']}: {sy['particles']} particles, {sy['springs']} springs, "
            f"{sy['dofs']} dofs ({sy['pinned']} pinned), forces: "
            f"{', '.join(sy['forces']) or 'springs only'}",
            f"method    {it['name']} (order {it['order']}, {kind}), dt {d['dt']:.4g}, "
            f"t_end {d['t_end']:.4g}",
        ]
        if it["implicit"]:
            ls = d["linear_solver"]
            pc = f" + {ls['preconditioner']}" if ls["preconditioner"] != "none" else ""
            lines.append(f"solver    {ls['method']}{pc}: {ls['linear_solves']} solves, "
                         f"{ls['iterations']} iterations, {ls['factorizations']} factorisations")
        step_ms = "" if d["step_time"] is None else f" ({1e3 * d['step_time']:.3g} ms/step)"
        stopped = f" (interrupted by {self.interrupted})" if self.interrupted else ""
        written = self.timings.get("output")
        written = "" if written is None else f", output {written:.3f} s"
        lines.append(f"steps     {d['steps']} of {d['steps_planned']}{stopped}, {d['frames']} frames, "
                     f"wall time {d['wall_time']:.3f} s{step_ms} (build + simulate){written}")
        lines.append(f"energy    drift {d['energy']['drift']:+.3e} (relative to scale "
                     f"{d['energy']['scale']:.3e}), max deviation {d['energy']['max_deviation']:.3e}")
        om = st["omega_max"]
        stab = f"omega_max {om:.4g}, h*omega_max {st['h_omega_max']:.3g}" if om is not None else ""
        if st["dt_crit"] is not None:
            stab += f", critical dt {st['dt_crit']:.4g}"
        verdict = st["verdict"] if self.instability is None else f"UNSTABLE: {self.failure}"
        if self.failed_step is not None:
            verdict = f"FAILED: {self.failure}"
        if st["dt_exceeds_critical"] and self.instability is None:
            verdict += " (but dt exceeds the critical step: growth may not have shown yet)"
        lines.append(f"verdict   {verdict}" + (f" ({stab})" if stab else ""))
        if self.contact is not None:
            lines.append(self.contact.summary_line())
        if self.output_dir is not None:
            lines.append(self.output_line())
        return lines


# ----------------------------------------------------------------------------- run

def run_scene(case: Case, output_dir: str | os.PathLike | None = None, quiet: bool = False,
              write: bool = True, echo: Callable[[str], Any] | None = None) -> SceneResult:
    """Run a prepared scene: build, simulate, write outputs, print the summary.

    Parameters
    ----------
    case : a scene from :func:`femkit.case.load_case`.
    output_dir : overrides ``output.dir``.
    quiet : print nothing (no summary, no progress) when true. Progress: a tqdm bar when stderr
        is a terminal, else one line per 10 % of the steps or per minute (elapsed, remaining).
        A stop request (``case.options.stop``, set by SIGINT/SIGTERM under ``femkit solve``)
        ends the run after the current step; the frames so far are written as usual, with
        ``interrupted: true`` in result.json.
    write : write the outputs (atomically) when true.
    echo : printing function (default :func:`print`).

    Returns
    -------
    SceneResult
        ``converged`` is false when the run became unstable or a step failed; the results up
        to the last good step are still written, marked ``"verdict": "unstable"`` (or
        ``"newton_failed"``, ``"solver_failed"``).
    """
    final = Path(output_dir or case.spec.output.dir).resolve()
    if write:  # refuse a bad output location before any work (never replaces user files)
        check_output_dir(final, EARLIER_RUN)
    check_scene_fits(case, system_size(case.spec.system))  # before anything is allocated
    out = echo or print
    timer = StageTimer()
    t0 = time.perf_counter()
    with timer("build"):
        system, triangles = build_system(case)
        integrator = build_integrator(case)
        ctx = build_context(case)
        every = output_every(case)
    st = case.spec.stability
    stop = case.options.stop
    # a tqdm bar on a terminal, else one line per 10 % or per minute on stderr (logs, batch jobs)
    progress = Progress(n_steps(case), f"scene {case.name}", unit="step", quiet=quiet)

    caught: list[str] = []
    instability = failed_step = None
    with contextlib.ExitStack() as outputs:
        # the output directory is built under a temporary name while the run goes on: frames
        # are written by a writer thread as they are recorded, the rest after the run; an
        # error anywhere removes it (nothing half-written), the earlier run stays
        tmp = outputs.enter_context(atomic_directory(final, EARLIER_RUN)) if write else None
        frames = None
        if write and case.spec.output.vtu:
            frames = outputs.enter_context(FrameStream(tmp, system, triangles))
        barrier = contact_force(system)
        recorder = None if barrier is None else ContactRecorder(barrier)
        on_record = None if frames is None else frames.add
        if recorder is not None:  # every recorded frame: distances, pairs, the independent check
            def on_record(k, t, x, v, _frames=frames):
                data = recorder.record(t, x)
                if _frames is not None:
                    _frames.add(k, t, x, v, point_data=data)
        with timer("simulate"), warnings.catch_warnings(record=True) as wlist:
            warnings.simplefilter("always", StabilityWarning)
            try:
                traj = simulate(system, integrator, case.spec.dt, case.spec.t_end, ctx=ctx,
                                record_every=every, energy_growth_limit=st.energy_growth_limit,
                                check_stability=st.check, check_every=st.check_every,
                                progress=progress, stop=stop,
                                on_record=on_record)
            except InstabilityError as exc:
                instability = exc
                traj = exc.partial
            except SolverError as exc:   # a failed step: the frames before it are kept
                if getattr(exc, "partial", None) is None:
                    raise
                failed_step, traj = exc, exc.partial
            for w in wlist:
                if issubclass(w.category, StabilityWarning):
                    caught.append(" ".join(str(w.message).split()))
                else:
                    warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)

        omega = None
        if st.check and traj.omega_max is None and system.n_springs:
            omega = float(estimate_omega_max(system, iters=200))
        result = SceneResult(case=case, system=system, integrator=integrator, trajectory=traj,
                             triangles=triangles, instability=instability, every=every,
                             wall_time=time.perf_counter() - t0, timings=timer.times,
                             omega_max=omega, warnings=caught, contact=recorder,
                             failed_step=failed_step)
        if not quiet:
            for w in caught:
                print(f"femkit: warning: {w}", file=sys.stderr)
        if write:
            # wall_time stays "build + simulate" as result.json and docs/scenes.md say; the
            # output stage (the last frames, the other files) has its own entry in the timings
            with timer("output"):
                write_scene_outputs(result, final, into=tmp, frames=frames)
    if instability is not None:
        print(f"femkit: unstable: {result.failure}", file=sys.stderr)
    elif failed_step is not None:
        print(f"femkit: failed: {result.failure}", file=sys.stderr)
    if not quiet:
        for line in result.summary_lines():
            out(line)
        for note in case.notes:  # e.g. a mesh file's unused nodes
            out(f"note      {note}")
        hint = fast_path_hint(case, system, integrator)
        if hint:
            out(hint)
    return result


#: Degrees of freedom from which an implicit scene on SuperLU is worth the Cholesky fast path
#: (Liu's 81 x 81 cloth, 19,683 dofs: 2-3x per step in benchmarks/bench_dynamics.py).
FAST_PATH_DOFS = 5_000


def fast_path_hint(case, system, integrator) -> str | None:
    """One line saying how to switch on the fast path when an implicit scene of at least
    :data:`FAST_PATH_DOFS` unknowns factorises with SuperLU (``method: direct``); else None.

    A barrier-contact scene is pointed at CHOLMOD (scikit-sparse, ``femkit[cholesky]``), which
    cuts its step (81 x 81 cloth on a sphere: 2.7 against 4.0 s CPU), not at cholespy, which is no
    faster there (docs/benchmarks.md, "Barrier contact")."""
    if (case.solver.method != "direct" or not getattr(integrator, "implicit", False)
            or system.ndof < FAST_PATH_DOFS):
        return None
    if any(getattr(f, "requires_bounded_steps", False) for f in system.forces):
        return ('hint      this contact scene factorises with SuperLU; the fast path is CHOLMOD: '
                'pip install "femkit[cholesky]" (scripts/install-cholesky.sh) and '
                'linear_solver: {method: cholesky}')
    return ('hint      this scene factorises with SuperLU; the fast path is pip install '
            '"femkit[fast]" and linear_solver: {method: cholesky, options: {engine: cholespy}}')
