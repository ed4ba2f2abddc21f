"""``kind: cloth_work_precision``: which implicit method buys the most accuracy per millisecond.

The cloth scenes named in ``scenes:`` (scene files, built by the scene layer; ``system_overrides``
merged into their ``system:`` block, e.g. a smaller grid) run with every method of ``methods:``
(fast mass-spring at 1..k iterations, its Chebyshev variant, Baraff-Witkin, Newton stopped after
1..k iterations) for ``frames`` steps of the scene's ``dt`` (or ``dt:``), through the linear solver
``linear_solver`` (default ``direct``, SuperLU; ``cholesky`` with the optional CHOLMOD is faster). The computation is
:func:`femkit.dynamics.work_precision.cloth_work_precision`: solve error against implicit Euler
solved by Newton to ``reference.tol`` at the same ``dt``, trajectory error against a small-``dt``
run (``reference.trajectory``, ``reference.substeps`` steps per frame), both per frame; cost = the
median wall time per frame. The report draws error per frame against time per frame (one line
per method family, the Pareto front highlighted) for both errors, and the energy history.
"""

from __future__ import annotations

import numpy as np

from ..case.specs import SOLVER_SCHEMA
from ..errors import CaseFileError, InputError
from ..kinds import KINDS

__all__ = ["cloth_schema", "check_cloth_study", "run_cloth_study", "build_cloth_report",
           "cloth_summary", "family_styles"]

_POS = {"type": "number", "exclusiveMinimum": 0}
_ITS = {"type": "array", "minItems": 1, "items": {"type": "integer", "minimum": 1}}

def cloth_schema() -> dict:
    """The kind's own keys (``kind``, ``title``, ``description``, ``output``, ``repeats`` and
    ``warmup`` are common to every study kind); the family enum is the keys of
    :data:`femkit.dynamics.work_precision.FAMILIES`."""
    from ..dynamics.work_precision import FAMILIES

    return _schema(sorted(FAMILIES))


def _schema(families: list) -> dict:
    return {
    "scenes": {"type": "array", "minItems": 1, "items": {"type": "string"},
               "description": "cloth scene files (relative to the study file)"},
    "system_overrides": {"type": "object", "description": "merged into every scene's system block"},
    "frames": {"type": "integer", "minimum": 1, "default": 30},
    "dt": {**_POS, "description": "frame length (default: each scene's dt)"},
    "linear_solver": {**SOLVER_SCHEMA, "default": {}},  # method: the kind's default_solver
    "methods": {"type": "array", "minItems": 1, "items": {
        "type": "object", "additionalProperties": False, "required": ["family"],
        "properties": {"family": {"enum": families},
                       "iterations": _ITS, "options": {"type": "object"},
                       "linear_solver": {**SOLVER_SCHEMA, "description":
                                         "this family's linear solver (default: the study's)"}}},
        "default": [{"family": "fast_mass_spring", "iterations": [1, 2, 3, 5, 10, 20]},
                    {"family": "chebyshev", "iterations": [3, 5, 10, 20]},
                    {"family": "baraff_witkin"},
                    {"family": "newton", "iterations": [1, 2, 3, 4]}]},
    "reference": {"type": "object", "additionalProperties": False, "default": {}, "properties": {
        "tol": {**_POS, "default": 1e-10},
        "solve": {"enum": ["newton", "local_global"], "default": "newton"},
        "trajectory": {"enum": ["newmark", "rk4"], "default": "newmark"},
        "substeps": {"type": "integer", "minimum": 2, "default": 16}}},
    }


_COLOURS = ("tab:blue", "tab:green", "tab:red", "tab:purple", "tab:orange", "tab:brown",
            "tab:pink", "tab:olive", "tab:cyan", "tab:gray")
_MARKERS = ("o", "s", "D", "^", "v", "P", "X", "*", "<", ">")


def family_styles() -> dict:
    """family -> (colour, marker), in the order of :data:`~femkit.dynamics.work_precision.FAMILIES`
    (a family added there gets the next style)."""
    from ..dynamics.work_precision import FAMILIES

    return {fam: (_COLOURS[i % len(_COLOURS)], _MARKERS[i % len(_MARKERS)])
            for i, fam in enumerate(FAMILIES)}


def _scene_case(study, path):
    from ..case import load_case

    overrides = {f"system__{k}": v for k, v in study.spec.system_overrides.items()}
    return load_case(study.resolve(path), **overrides)


def check_cloth_study(study) -> None:
    """The load-time checks; builds ``study.spec`` (:class:`femkit.study.spec.ClothStudySpec`)
    with the solver specs (the study's and each family's) validated once."""
    from ..case.specs import solver_spec
    from ..dynamics.work_precision import expand_methods
    from .spec import ClothStudySpec

    d = study.data
    default = KINDS.get(study.kind, "kind").default_solver
    methods = _methods(d["methods"], default)
    try:
        expand_methods(methods)
    except InputError as exc:
        raise CaseFileError(f"methods: {exc}") from None
    ls = solver_spec(d["linear_solver"], "linear_solver", default_method=default)
    study.spec = spec = ClothStudySpec.from_data(d, ls, methods)
    for i, p in enumerate(spec.scenes):
        path = study.resolve(p)
        if not path.is_file():
            raise CaseFileError(f"scenes[{i}]: scene file not found: {path}")
        study.files.append(path)
        case = _scene_case(study, p)
        if case.problem != "mass_spring" or case.spec.system["type"] != "cloth":
            raise CaseFileError(f"scenes[{i}]: {path.name} is not a cloth scene (system.type: cloth)")


def _methods(methods: list, default: str) -> list:
    """The method list with each family's own ``linear_solver`` mapping as a SolverSpec
    (validated like every solver spec: a typo names the key and the valid ones; ``default``: the
    method when a mapping names none, the kind's ``default_solver``)."""
    from ..case.specs import solver_spec

    return [{**m, "linear_solver": solver_spec(m["linear_solver"], f"methods[{i}].linear_solver",
                                               default_method=default)}
            if "linear_solver" in m else m for i, m in enumerate(methods)]


def run_cloth_study(study, progress_enabled=None) -> dict:
    """The sweep: one record per (scene, method setting), energies and references per scene."""
    from ..case.scene.run import build_system
    from ..dynamics.work_precision import cloth_work_precision
    from .pareto import pareto_front
    from ..dynamics.work_precision import expand_methods
    from ..interrupt import checkpoint
    from ..progress import Progress

    d = study.spec
    spec = d.linear_solver
    ref = d.reference
    records, energy, references, notes = [], {}, [], []
    # one progress unit per method run (one record each); the remaining time is scaled by each
    # scene's springs (its references and runs cost in proportion to them)
    per_scene = len(expand_methods([dict(m) for m in d.methods]))
    scenes = [(case, build_system(case)[0]) for case in (_scene_case(study, p) for p in d.scenes)]
    bar = Progress(per_scene * len(scenes), "cloth runs", unit="run", quiet=progress_enabled is False,
                   cost=per_scene * sum(system.n_springs for _, system in scenes))
    with bar:  # closes the bar, saying where a stop request ended the runs
        for case, system in scenes:
            checkpoint(f"before scene {case.name}")
            n_springs = system.n_springs
            dt = float(d.dt or case.spec.dt)
            name = case.name
            out = cloth_work_precision(system, dt, d.frames, [dict(m) for m in d.methods], solver=spec,
                                       reference_tol=ref.tol, trajectory_reference=ref.trajectory,
                                       substeps=ref.substeps, reference_solve=ref.solve,
                                       progress=lambda label, c=n_springs: bar.update(cost=c))
            runs = out["runs"]
            cost = [r.time_per_frame for r in runs]
            front_s = set(pareto_front(cost, [r.solve_error for r in runs]).tolist())
            front_t = set(pareto_front(cost, [r.trajectory_error for r in runs]).tolist())
            for i, r in enumerate(runs):
                records.append({"scene": name, "nodes": system.n, "springs": system.n_springs, "dt": dt,
                                "frames": d.frames, **r.summary(),
                                "options": ", ".join(f"{k}={v}" for k, v in r.options.items()),
                                "pareto_solve": i in front_s, "pareto_trajectory": i in front_t})
            energy[name] = {"times": out["times"], "runs": {r.label: r.energy for r in runs},
                            "implicit_euler": out["reference"]["implicit_euler"]["energy"],
                            "trajectory": out["reference"]["trajectory"]["energy"]}
            ie, tr = out["reference"]["implicit_euler"], out["reference"]["trajectory"]
            references.append({"scene": name, "implicit_euler_solve": ie["solve"],
                               "implicit_euler_tol": ie["tol"],
                               "implicit_euler_time_per_frame": ie["time_per_frame"],
                               "trajectory_method": tr["method"], "trajectory_substeps": tr["substeps"],
                               "trajectory_time_per_frame": tr["time_per_frame"],
                               "implicit_euler_trajectory_error": tr["error_vs_implicit_euler"]})
            notes.append(f"{name}: implicit Euler itself ({ie['solve']} to tol {ie['tol']:g}) is "
                         f"{tr['error_vs_implicit_euler']:.3g} per frame from the {tr['method']} "
                         f"reference (dt/{tr['substeps']}): no implicit-Euler-based method can have a "
                         "smaller trajectory error than about that.")
    return {"records": records, "tables": {"references": references}, "notes": notes,
            "energy": energy}


def _figure(path, title: str, recs: list, energy: dict) -> None:
    """Three panels: solve error and trajectory error per frame against time per frame (one line
    per family, Pareto front as a band), energy history."""
    from ..dynamics.work_precision import FAMILIES
    from ..io.figures import new_figure, save_figure

    fig = new_figure(15.0, 4.6, layout="constrained")
    axes = fig.subplots(1, 3)
    for ax, key, front_key, what in ((axes[0], "solve_error", "pareto_solve",
                                      "solve error vs implicit Euler (same dt)"),
                                     (axes[1], "trajectory_error", "pareto_trajectory",
                                      "trajectory error vs small-dt reference")):
        front = sorted((r["time_per_frame"], r[key]) for r in recs if r[front_key])
        if front:
            ft, fe = np.array(front).T
            ax.step(ft, fe, where="post", color="gold", linewidth=8, alpha=0.5, zorder=0,
                    label="Pareto front")
        for fam, (color, marker) in family_styles().items():
            rows = [r for r in recs if r["family"] == fam and not r["failed"]]
            if rows:
                ax.plot([r["time_per_frame"] for r in rows], [r[key] for r in rows], color=color,
                        marker=marker, label=FAMILIES[fam][0])
                for r in rows:
                    if r["setting"] is not None:
                        ax.annotate(str(r["setting"]), (r["time_per_frame"], r[key]), fontsize=7,
                                    xytext=(3, 3), textcoords="offset points", color=color)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time per frame [s] (median)")
        ax.set_ylabel("error per frame (max node / box diagonal, mean over frames)")
        ax.set_title(what, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    ax = axes[2]
    t = np.asarray(energy["times"])
    e0 = energy["implicit_euler"][0]
    ax.plot(t, np.asarray(energy["trajectory"]) - e0, color="black", linewidth=2, label="small-dt reference")
    ax.plot(t, np.asarray(energy["implicit_euler"]) - e0, color="0.5", linestyle="--",
            label="implicit Euler (solved tightly)")
    for fam, (color, marker) in family_styles().items():
        rows = [r for r in recs if r["family"] == fam and not r["failed"]]
        if rows:  # the cheapest and the most accurate setting of each family
            for r, ls in ((rows[0], ":"), (rows[-1], "-")) if len(rows) > 1 else ((rows[0], "-"),):
                ax.plot(t, np.asarray(energy["runs"][r["label"]]) - e0, color=color, linestyle=ls,
                        label=r["label"], linewidth=1)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("total energy E(t) - E(0) [J]")
    ax.set_title("energy history (implicit methods damp)", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=6)
    fig.suptitle(title)
    save_figure(fig, path)


def build_cloth_report(report, study, result, data, stage) -> None:
    recs = result.records
    report.paragraph("Error per frame: the largest node position error divided by the bounding-box "
                     "diagonal of the initial cloth, averaged over the frames. Solve error: against "
                     "implicit Euler solved by Newton to a tight tolerance at the same dt (what each "
                     "method loses by solving the backward-Euler equations approximately). Trajectory "
                     "error: against a small-dt run of a second-order method (what a user sees). "
                     "Time: median wall time per frame after the first.")
    for scene in dict.fromkeys(r["scene"] for r in recs):
        rows = [r for r in recs if r["scene"] == scene]
        report.heading(f"Scene {scene} ({rows[0]['nodes']} nodes, {rows[0]['springs']} springs, "
                       f"dt = {rows[0]['dt']:.4g}, {rows[0]['frames']} frames)")
        fig = f"figures/{scene}_work_precision.png"
        _figure(stage / fig, f"Cloth work-precision: {scene}", rows, data["energy"][scene])
        report.figure(fig, "Error per frame against time per frame (numbers: iterations), Pareto "
                           "fronts highlighted; energy history of the cheapest (dotted) and most "
                           "accurate (solid) setting of each family")
        cols = ["label", "time_per_frame", "solve_error", "trajectory_error", "pareto_solve",
                "pareto_trajectory", "failed"]
        report.table(cols, [[r[c] for c in cols] for r in rows])


def cloth_summary(result) -> list[str]:
    lines = []
    for scene in dict.fromkeys(r["scene"] for r in result.records):
        rows = [r for r in result.records if r["scene"] == scene]
        for key, what in (("pareto_solve", "solve"), ("pareto_trajectory", "trajectory")):
            front = [r["label"] for r in sorted(rows, key=lambda r: r["time_per_frame"]) if r[key]]
            lines.append(f"{scene}: Pareto front ({what} error): {', '.join(front)}")
    return lines
