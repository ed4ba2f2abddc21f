"""``kind: adaptive``: uniform against adaptive refinement of one Poisson problem.

The same solver, from the same initial mesh: red (uniform) refinement, and the adaptive loop
(:func:`femkit.fem.adaptive.adaptive_solve`: estimator, Dörfler marking, newest-vertex bisection,
nested iteration) for each listed estimator. Per level it records dofs, the estimate, the true
energy-norm error and the effectivity when the problem gives ``exact.grad``, solver iterations and
the wall time since the run started. The fitted rates are those of the error (the true one when
known, else the estimate) against dofs and against run time. Both runs stop at ``max_dofs`` (or
``target``, ``max_time``); uniform levels grow four-fold, so its last level may be smaller.
"""

from __future__ import annotations

from ...interrupt import active_flag
from ...progress import progress
from ..fit import fit_rate

__all__ = ["run"]


def run(study, progress_enabled=None) -> dict:
    """The sweep: one adaptive run per estimator and one uniform run; records, fits, final meshes."""
    from ...case.poisson.run import exact_gradient
    from ...fem.adaptive import adaptive_solve, problem_solver
    from ..problem import study_problem

    d = study.spec
    spec = study_problem(study, need_exact=False)
    solver = study.solvers[0]
    mesh0 = spec.base_mesh(d.h0)
    grad = exact_gradient(spec.case)
    solve_on = problem_solver(spec.problem, solver.solve, solver.method)
    solve_on(mesh0, None)                                   # warm-up: imports, AMG, caches
    records, fits, meshes, outcome = [], [], {}, []
    measured = "error" if grad is not None else "estimate"
    for label, refinement, est in progress(list(d.runs()), desc="adaptive loops", unit="loop",
                                             enabled=progress_enabled, stop=active_flag()):
        run = adaptive_solve(solve_on, mesh0, theta=d.theta, target=d.target,
                             max_dofs=d.max_dofs, max_time=d.max_time,
                             max_levels=d.max_levels, estimator=est, refinement=refinement,
                             grad_exact=grad)
        meshes[label] = (run.mesh, run.estimate.indicators)
        outcome.append({"run": label, "levels": len(run.levels), "dofs": run.levels[-1].dofs,
                        "estimate": run.levels[-1].estimate, "error": run.levels[-1].error,
                        "total_time": run.total_time, "target_met": run.target_met,
                        "stop_reason": run.stop_reason})
        for lv in run.levels:
            records.append({"run": label, "refinement": refinement, "estimator": est, **lv.as_dict(),
                            "measured": lv.error if grad is not None else lv.estimate})
        rows = [r for r in records if r["run"] == label and r["dofs"] >= d.fit_min_dofs]
        if len(rows) >= 2:
            y = [r["measured"] for r in rows]
            for against, key in (("dofs", "dofs"), ("time", "elapsed")):
                f = fit_rate([r[key] for r in rows], y)
                fits.append({"run": label, "error": measured, "against": against, **f.as_dict(), "fit": f})
    notes = []
    if grad is None:
        notes.append("No exact solution: the error axis is the estimate (of the estimator named in "
                     "each run; uniform uses the first). Its reliability is what the bundled cases with "
                     "an exact solution measure (effectivity, docs/methods.md section 4).")
    return {"records": records, "fits": fits, "tables": {"outcome": outcome}, "notes": notes,
            "meshes": meshes, "measured": measured}

