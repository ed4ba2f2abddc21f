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

from .spec import scene_case

__all__ = ["run"]


def run(study, progress_enabled=None) -> dict:
    """The sweep: one record per (scene, method setting), energies and references per scene."""
    from ...case.scene.run import build_system
    from ...dynamics.work_precision import cloth_work_precision
    from ..pareto import pareto_front
    from ...dynamics.work_precision import expand_methods
    from ...interrupt import checkpoint
    from ...progress import Progress

    d = study.spec
    spec = d.linear_solver
    ref = d.reference
    records, energy, references, notes = [], {}, [], []
    # one progress unit per method run (one record each); the remaining time is scaled by each
    # scene's springs (its references and runs cost in proportion to them)
    per_scene = len(expand_methods([dict(m) for m in d.methods]))
    scenes = [(case, build_system(case)[0]) for case in (scene_case(study, p) for p in d.scenes)]
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

