"""Cost model of a mass-spring scene: steps, frames, memory, output and time.

* steps ``= round((t_end - t0) / dt)``; frames recorded ``= floor(steps / every) + 1`` plus the
  last step (what :func:`femkit.dynamics.simulate.simulate` keeps in memory and the scene writes);
  the cadence ``every`` is a number the caller computed (a scene file's ``output`` is turned into
  it once, by :func:`femkit.case.scene.spec.record_every`);
* memory: the recorded trajectory (positions, velocities: ``2 d`` floats per node and frame,
  plus energies and momentum), the system (``bytes.system_per_spring``) and, for implicit
  integrators, the matrices and their factorisation (``scene.implicit_bytes_per_spring``);
* output: per frame ``frame_file_bytes_fixed`` plus ``..._per_node`` and ``..._per_spring``
  (``.vtu`` frames or XDMF), ``energy.csv`` per frame, a GIF of at most 60 frames (fitted on
  the bundled scenes: rope, soft disk, hanging cloth, Liu's cloth, within 17 %);
* time: ``steps x`` the seconds of one step, measured on a first batch of steps by the caller
  (``femkit.case.cost.measure_step_seconds``) when given, else the calibrated per-spring
  constant.

>>> p = plan_scene(n_nodes=100, n_springs=300, dim=3, dt=1e-9, t_end=2.0, every=40_000_000)
>>> p.steps, p.sizes["frames"]
(2000000000, 51)
"""

from __future__ import annotations

import math

from ..errors import InputError
from .constants import load_constants
from .plan import Plan, Stage, format_seconds, round_down, round_up

__all__ = ["plan_scene"]

_FLOAT = 8


def plan_scene(*, n_nodes: int, n_springs: int, dim: int, dt: float, t_end: float,
               t0: float = 0.0, every: int = 1, outputs=("vtu", "energy_csv"),
               method: str = "", implicit: bool = False, step_seconds: float | None = None,
               name: str = "scene", constants: dict | None = None, speed: float = 1.0) -> Plan:
    """Predict a scene's cost (see the module docstring).

    Parameters
    ----------
    n_nodes, n_springs, dim : the system's size
    dt, t_end, t0 : the time grid
    every : steps between recorded frames (the start and the last step are recorded too)
    outputs : any of ``vtu``, ``xdmf``, ``energy_csv``, ``png``, ``gif``
    method, implicit : the integrator (name for the title; implicit ones cost more per step)
    step_seconds : measured seconds per step (first batch); ``None`` = calibrated constant
    speed : seconds multiplier of this machine (used only without ``step_seconds``)

    Raises
    ------
    InputError
        Non-positive or non-finite ``dt``, ``t_end < t0``.
    """
    c = constants or load_constants()
    sc = c["scene"]
    dt, t_end = float(dt), float(t_end)
    if not (math.isfinite(dt) and dt > 0):
        raise InputError(f"dt must be a positive finite number, got {dt}")
    if not (math.isfinite(t_end) and t_end >= t0):
        raise InputError(f"t_end must be finite and >= t0 = {t0}, got {t_end}")
    n, s, d = int(n_nodes), int(n_springs), int(dim)
    steps = int(round((t_end - t0) / dt))
    every_n = max(int(every), 1)
    recorded = steps // every_n + 1 + (1 if steps % every_n else 0)
    frame_mem = (2 * d * n + 5 + d) * _FLOAT
    measured = step_seconds is not None
    per_step = (float(step_seconds) if measured else
                speed * ((sc.get("implicit_step_seconds_fixed", sc["step_seconds_fixed"]) + sc[
                    "implicit_step_seconds_per_spring"] * s) if implicit else
                         (sc["step_seconds_fixed"] + sc["step_seconds_per_spring"] * s)))
    sys_bytes = (sc["system_bytes_per_spring"] + (sc["implicit_bytes_per_spring"] if implicit else 0.0)) * s
    traj_bytes = frame_mem * recorded
    stages = [Stage("simulate", per_step * steps, sys_bytes + traj_bytes,
                    detail=f"{steps:,} steps of {method or 'the integrator'}, "
                    f"{format_seconds(per_step)} per step ({'measured' if measured else 'model'})")]
    outs = tuple(outputs or ())
    unknown = sorted(set(outs) - {"vtu", "xdmf", "energy_csv", "png", "gif"})
    if unknown:
        raise InputError(f"unknown scene output(s) {unknown}; valid: energy_csv, gif, png, vtu, xdmf")
    frame_file = (sc["frame_file_bytes_fixed"] + sc["frame_file_bytes_per_node"] * n
                  + sc["frame_file_bytes_per_spring"] * s)
    out_bytes = 0.0
    if "vtu" in outs:
        out_bytes += frame_file * recorded
    if "xdmf" in outs:
        out_bytes += frame_file * recorded
    if "energy_csv" in outs:
        out_bytes += sc["energy_csv_bytes_per_frame"] * recorded
    if "gif" in outs:
        out_bytes += sc["gif_bytes_per_frame"] * min(recorded, 60)
    if "png" in outs:
        out_bytes += c["output_bytes"]["png"]
    if outs:
        secs = sc["frame_write_seconds_per_byte"] * out_bytes * speed
        stages.append(Stage("output", secs, sys_bytes + traj_bytes + frame_file, out_bytes,
                            detail=f"{recorded:,} frames: {', '.join(outs)}"))
    sizes = {"nodes": n, "springs": s, "steps": steps, "frames": recorded}
    assumptions = [f"steps = (t_end - t0) / dt = {t_end - t0:g} / {dt:g}; a frame every {every_n} steps",
                   "time per step " + ("measured on a first batch of steps" if measured else
                                       "from the calibrated per-spring constant (femkit/cost/constants.json)")]
    plan = Plan("scene", f"{name}: {method or 'integrator'}, dt={dt:g}, t_end={t_end:g}", sizes, stages,
                c["bytes"]["baseline"], assumptions)

    def suggest(what: str, limit: float) -> str:
        if what == "steps":
            return (f"dt >= {round_up(dt * steps / limit)} or t_end <= {round_down(t0 + limit * dt)}")
        if what == "time":
            k = limit / max(plan.seconds, 1e-300)
            return f"dt >= {round_up(dt / k)} or t_end <= {round_down(t0 + (t_end - t0) * k)}"
        if what == "memory" and sys_bytes >= traj_bytes:
            return "fewer nodes and springs (a smaller system)"
        if what in ("output", "memory"):
            return "fewer frames (output.frames / output.every) or fewer output kinds"
        return ""

    plan.suggest = suggest
    return plan
