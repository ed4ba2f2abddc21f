"""Report of a ``heat_work_precision`` study: error at t_end against run time and against dt,
one line per (integrator, mesh), the explicit schemes' stability barrier drawn."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["build", "summary"]


def _lines(records):
    """``(integrator, h) -> rows`` in dt order (coarse first)."""
    out = {}
    for r in records:
        out.setdefault((r["integrator"], r["h"]), []).append(r)
    return {k: sorted(v, key=lambda r: -r["dt"]) for k, v in out.items()}


def _figure(path, title: str, records) -> None:
    from ...io.figures import new_figure, save_figure

    fig = new_figure(11.0, 4.6)
    ax1, ax2 = fig.subplots(1, 2)
    hs = sorted({r["h"] for r in records}, reverse=True)
    names = list(dict.fromkeys(r["integrator"] for r in records))
    colours = {n: f"C{i}" for i, n in enumerate(names)}
    styles = {h: ls for h, ls in zip(hs, ("-", "--", "-.", ":"))}
    finite = [r["error"] for r in records if r["error"] is not None and math.isfinite(r["error"])]
    cap = 10.0 * max([e for e, r in zip(finite, records) if r["stable"]] or [1.0])
    for (name, h), rows in _lines(records).items():
        st = dict(color=colours[name], ls=styles[h])
        ok = [r for r in rows if r["stable"] and r["error"]]
        bad = [r for r in rows if not r["stable"]]
        label = f"{name}, h = {h:g}"
        ax1.plot([r["seconds"] for r in ok], [r["error"] for r in ok], marker="o", ms=4,
                 label=label, **st)
        ax2.plot([r["dt"] for r in ok], [r["error"] for r in ok], marker="o", ms=4, label=label, **st)
        for ax, key in ((ax1, "seconds"), (ax2, "dt")):
            if bad:
                ax.scatter([r[key] for r in bad], [min(cap, r["error"] or cap) if
                                                   math.isfinite(r["error"] or math.inf) else cap
                                                   for r in bad],
                           marker="x", s=50, color=colours[name])
    for h in hs:  # the barrier: the explicit schemes' critical step on each mesh
        crit = [r["dt_critical"] for r in records if r["h"] == h and r["explicit"] and r["dt_critical"]]
        if crit:
            ax2.axvline(min(crit), color="0.3", ls=styles[h], lw=1)
            ax2.annotate(f"dt_crit (h = {h:g})", (min(crit), cap), rotation=90, fontsize=7,
                         va="top", ha="right", color="0.3")
    for ax, xl in ((ax1, "run time: assembly + steps [s]"), (ax2, "dt")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xl)
        ax.set_ylabel("L2 error at t_end")
        ax.grid(True, which="both", alpha=0.3)
    ax1.set_title("work-precision (lower left wins; x: unstable, capped)", fontsize=9)
    ax2.set_title("error against dt (x: above the critical step)", fontsize=9)
    ax2.legend(fontsize=7, loc="lower right")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    save_figure(fig, path)


def _slopes(records) -> list:
    """Per (integrator, h): the slope of log error against log dt over its stable runs whose
    error is at least 3 x the finest run's (the time error dominates the space error there)."""
    rows = []
    for (name, h), rs in _lines(records).items():
        ok = [r for r in rs if r["stable"] and r["error"]]
        floor = 3.0 * min((r["error"] for r in ok), default=0.0)
        use = [r for r in ok if r["error"] >= floor]
        slope = (float(np.polyfit(np.log([r["dt"] for r in use]), np.log([r["error"] for r in use]), 1)[0])
                 if len(use) >= 2 else None)
        rows.append([name, h, len(ok), len(rs) - len(ok), slope])
    return rows


def build(report, study, result, data, stage) -> None:
    recs = result.records
    report.paragraph("Each integrator of the heat kind on the base case at every mesh size h and "
                     "step dt: the L2 error against the exact solution at t_end, against the run's "
                     "assembly + steps time (best of the repeats) and against dt. An explicit "
                     "scheme above its critical step on the mesh (2 / lambda_max(M^-1 K), which "
                     "shrinks as h^2) is run anyway and drawn as x: the stability barrier. On a "
                     "finer mesh the barrier moves to smaller dt while the implicit schemes keep "
                     "every dt: why implicit wins on stiff problems.")
    _figure(stage / "figures/heat_work_precision.png", study.title, recs)
    report.figure("figures/heat_work_precision.png",
                  "Left: error at t_end against run time. Right: error against dt, with the "
                  "critical step of the explicit scheme on each mesh")
    report.heading("Fitted time orders")
    report.table(["integrator", "h", "stable runs", "unstable runs", "slope of error vs dt"],
                 _slopes(recs))
    cols = ["h", "integrator", "dt", "steps", "seconds", "error", "stable", "dt_critical"]
    report.heading("Runs")
    report.table(cols, [[r[c] for c in cols] for r in recs])


def summary(result) -> list[str]:
    out = []
    for name, h, ok, bad, slope in _slopes(result.records):
        s = "-" if slope is None else f"{slope:.2f}"
        out.append(f"{name}, h = {h:g}: {ok} stable runs, {bad} unstable, order in dt {s}")
    return out
