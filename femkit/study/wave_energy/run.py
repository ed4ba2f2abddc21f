"""Runs of a ``wave_energy`` study: every (integrator, step count) through the wave kind's
pipeline (:func:`femkit.case.wave.run.run_wave`, nothing written, up to :data:`FRAMES` frames
evenly spaced), the relative drift ``max_t |E(t) - E(0)| / E(0)`` of ``E = 1/2 v^T M v +
1/2 u^T K u`` over those frames. A step
count whose dt is above an explicit scheme's critical step is run anyway and marked unstable."""

from __future__ import annotations

from ..spec import load_base_case as base_case

__all__ = ["run", "FRAMES"]

#: Frames per run at which the energy is sampled (each frame also costs the error norms when
#: the base case gives ``exact``).
FRAMES = 50


def run(study, progress_enabled=None) -> dict:
    """One record per run: integrator, steps, dt, energy drift, final energy ratio, stable."""
    from ...progress import Progress

    d = study.spec
    records, notes = [], []
    bar = Progress(len(d.schemes) * len(d.steps), "wave_energy", unit="run",
                   quiet=progress_enabled is False)
    _, base = base_case(study)
    for name in d.schemes:
        for n in d.steps:
            _, case = base_case(study, integrator=name, dt=base.spec.t_end / n,
                                output={"frames": min(n, FRAMES)})
            res = case.with_options(force=True).run(write=False, quiet=True)
            crit = res.stability.get("dt_critical")
            stable = res.converged and (crit is None or res.case.spec.dt <= crit)
            E = [e["total"] for e in res.energies]
            drift = max(abs(e - E[0]) for e in E) / abs(E[0]) if E and E[0] else None
            records.append({"integrator": name, "steps": n, "dt": res.case.spec.dt,
                            "drift": drift, "final_ratio": E[-1] / E[0] if E and E[0] else None,
                            "stable": stable, "dt_critical": crit,
                            "seconds": res.timings.get("steps", 0.0)})
            if not stable:
                notes.append(f"{name}, {n} steps (dt = {res.case.spec.dt:.4g}): above the "
                             f"critical step {crit:.4g}, unstable")
            bar.update()
    bar.close()
    return {"records": records, "notes": notes}
