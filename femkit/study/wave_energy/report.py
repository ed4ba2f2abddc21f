"""Report of a ``wave_energy`` study: energy drift against the step count, per integrator."""

from __future__ import annotations

__all__ = ["build", "summary"]


def build(report, study, result, data, stage) -> None:
    from .. import figures as F

    recs = result.records
    names = list(dict.fromkeys(r["integrator"] for r in recs))
    report.paragraph("The discrete energy E = 1/2 v^T M v + 1/2 u^T K u of the base case, run "
                     "with each integrator over the same t_end in a growing number of steps: "
                     "its largest relative change over the run. Newmark's average acceleration "
                     "and the variational (midpoint) integrator conserve it to round-off without "
                     "load; central difference keeps it bounded (it conserves a modified energy) "
                     "with an error falling as dt^2; implicit Euler dissipates it, less as dt "
                     "falls. Runs above central difference's critical step are left out of the "
                     "figure and listed.")
    series = [{"label": n, "x": [r["steps"] for r in recs if r["integrator"] == n and r["stable"]],
               "y": [max(r["drift"] or 0.0, 1e-16) for r in recs
                     if r["integrator"] == n and r["stable"]]} for n in names]
    F.loglog_figure(stage / "figures" / "energy_drift.png", series,
                    title="Wave equation: energy drift against step count",
                    xlabel="steps over t_end", ylabel="max |E(t) - E(0)| / E(0)")
    report.figure("figures/energy_drift.png", "Relative energy drift against the step count "
                                              "(round-off floor 1e-16)")
    cols = ["integrator", "steps", "dt", "drift", "final_ratio", "stable", "dt_critical", "seconds"]
    report.table(cols, [[r[c] for c in cols] for r in recs])


def summary(result) -> list[str]:
    out = []
    for name in dict.fromkeys(r["integrator"] for r in result.records):
        rows = [r for r in result.records if r["integrator"] == name and r["stable"]]
        if rows:
            out.append(f"{name}: energy drift {rows[0]['drift']:.3g} ({rows[0]['steps']} steps) -> "
                       f"{rows[-1]['drift']:.3g} ({rows[-1]['steps']} steps)")
        else:
            out.append(f"{name}: no stable run")
    return out
