"""Runs of a ``heat_work_precision`` study: every (mesh size, integrator, dt) through the heat
kind's pipeline (:func:`femkit.case.heat.run.run_heat`, nothing written), timed as the run's
assembly, stability check and steps (the mesh and the error norms are not the integrator's
work). An explicit scheme above its critical step runs anyway (``force``) and is recorded
``stable: false``: the barrier the figure shows."""

from __future__ import annotations

from ..spec import load_base_case as base_case

__all__ = ["run"]

#: The stages of a heat run that are the integrator's work.
TIMED = ("assembly", "stability", "steps")


def run(study, progress_enabled=None) -> dict:
    """One record per run: mesh size, integrator, dt, the error at ``t_end``, seconds, dt_crit."""
    from ...progress import Progress

    d = study.spec
    records, notes = [], []
    bar = Progress(len(d.h) * len(d.schemes) * len(d.dt), "heat_work_precision",
                   unit="run", quiet=progress_enabled is False)
    for h in d.h:
        for name in d.schemes:
            for dt in d.dt:
                _, case = base_case(study, mesh={"h": h}, integrator=name, dt=dt,
                                    output={"frames": 1})
                case = case.with_options(force=True)
                best = None
                for _ in range(max(1, study.spec.repeats)):
                    res = case.run(write=False, quiet=True)
                    secs = sum(res.timings.get(k, 0.0) for k in TIMED)
                    best = secs if best is None else min(best, secs)
                crit = res.stability.get("dt_critical")
                stable = res.converged and (crit is None or res.case.spec.dt <= crit)
                err = res.errors["final"]["L2"] if res.errors else None
                records.append({"h": h, "integrator": name, "dt": res.case.spec.dt,
                                "steps": res.march.steps, "seconds": best, "error": err,
                                "stable": stable,
                                "dt_critical": crit,
                                "explicit": bool(res.scheme.explicit),
                                "unknowns": int(res.mesh.n_points)})
                if not stable:
                    notes.append(f"h = {h:g}, {name}, dt = {res.case.spec.dt:.4g} above the "
                                 f"critical step {crit:.4g}: unstable"
                                 + (f" ({res.march.failure})" if res.march.failure else ""))
                bar.update()
    bar.close()
    return {"records": records, "notes": notes}
