"""Report of a ``dynamics_work_precision`` study: orders, runs, four figures."""

from __future__ import annotations

import numpy as np

from .. import figures as F
from ..pareto import pareto_front
from ..summary import fit_lines

FAMILY_LINES = {"explicit": "-", "symplectic": "--", "implicit": "-."}
LEGEND_TITLE = "solid: explicit, dashed: symplectic, dash-dot: implicit"


def _dt_range(dts) -> str:
    """``2^-6 .. 2^-10 (5)`` for powers of two, else ``0.02 .. 0.005 (3)``."""
    def one(dt):
        k = -np.log2(dt)
        return f"2^-{k:.0f}" if abs(k - round(k)) < 1e-9 else f"{dt:.3g}"

    return f"{one(max(dts))} .. {one(min(dts))} ({len(dts)})"


def integrator_family(name: str, **options) -> str:
    """``"symplectic"``, ``"implicit"`` or ``"explicit"`` (a symplectic implicit method counts as symplectic)."""
    from ...dynamics.integrators import get_integrator

    integ = get_integrator(name, **options)
    if getattr(integ, "symplectic", False):
        return "symplectic"
    return "implicit" if getattr(integ, "implicit", False) else "explicit"


def integrator_styles(study) -> dict:
    """Label -> line style: one colour + marker per integrator, line style per family."""
    book = F.StyleBook(FAMILY_LINES)
    styles = {}
    for spec in study.integrators:
        styles[spec.label] = book(spec.label, integrator_family(spec.method, **spec.options))
    return styles


def build(report, study, result, data, stage) -> None:
    recs = result.records
    scene = study.spec.scene
    labels = list(dict.fromkeys(r["integrator"] for r in recs))
    fits = {f["integrator"]: f for f in result.fits}
    styles = integrator_styles(study)
    report.paragraph(f"Scene: {scene.type} (k = {scene.k:g}, m = {scene.mass:g}, t_end = {scene.t_end:g}); "
                     f"dt = {', '.join(f'{dt:.4g}' for dt in data['dts'])}.")
    report.heading("Fitted orders")
    report.paragraph("Least-squares slope of log(max position error over the trajectory) against log(dt) over the "
                     "asymptotic range: stable runs above the round-off floor, coarsest dt dropped until the fit has "
                     "R² >= 0.999 and every local slope in the range is within 0.05 of it (at least 3 dt kept; "
                     "'no' in the asymptotic column: even the finest 3 fail the test). Local slopes between "
                     "consecutive dt, coarse to fine, over all dt; the declared order is the integrator's own. "
                     "Unstable runs are excluded from the fits (listed below).")
    report.table(["integrator", "declared order", "fitted order", "std. error", "R²", "dt used", "dropped",
                  "local slopes", "asymptotic"],
                 [[f["integrator"], f["declared_order"], f["slope"], f["slope_stderr"], f["r2"],
                   _dt_range(f["dt_used"]), len(f["dt_dropped"]),
                   " ".join(f"{v:.2f}" for v in f["local_slopes"]), f["asymptotic"]]
                  for f in result.fits])
    unstable = [r for r in recs if not r["stable"]]
    report.heading("Unstable runs")
    if unstable:
        report.paragraph("These runs are excluded from the fitted orders and the work-precision figure.")
        report.table(["integrator", "dt", "dt * omega_max", "critical dt", "what happened"],
                     [[r["integrator"], r["dt"], r["h_omega"], r["dt_crit"], r["reason"]] for r in unstable])
    else:
        report.paragraph("None: every run completed within the energy-growth limit.")

    report.heading("Figures")
    series = []
    for lab in labels:
        rows = [r for r in recs if r["integrator"] == lab and r["stable"]]
        series.append({"label": lab, "x": [r["dt"] for r in rows], "y": [r["error_max"] for r in rows],
                       "fit": fits.get(lab, {}).get("fit"), "style": styles.get(lab)})
    F.loglog_figure(stage / "figures" / "error_vs_dt.png", series,
                    title="Convergence of the integrators: error vs time step",
                    xlabel="time step dt [s]", ylabel="max position error over the trajectory [m]",
                    triangle=2, note="dotted: fitted order; triangle: slope 2", legend_title=LEGEND_TITLE)
    report.figure("figures/error_vs_dt.png", "Error against dt, fitted orders in the legend (unstable runs omitted)")

    wp, t_all, e_all, idx = [], [], [], []
    for lab in labels:
        rows = [r for r in recs if r["integrator"] == lab and r["stable"]]
        wp.append({"label": lab, "x": [r["wall_time"] for r in rows], "y": [r["error_max"] for r in rows],
                   "style": styles.get(lab)})
        for r in rows:
            t_all.append(r["wall_time"])
            e_all.append(r["error_max"])
            idx.append(recs.index(r))
    front = pareto_front(t_all, e_all)
    F.work_precision_figure(stage / "figures" / "work_precision.png", wp, front=[(t_all[i], e_all[i]) for i in front],
                            title="Work-precision of the integrators: error vs run time",
                            xlabel="wall time per run [s] (min over repeats)",
                            ylabel="max position error over the trajectory [m]", legend_title=LEGEND_TITLE)
    report.figure("figures/work_precision.png", "Work-precision: error against wall time, Pareto front highlighted")
    on_front = {idx[i] for i in front}
    for i, r in enumerate(recs):
        r["pareto"] = i in on_front

    dts = data["dts"]
    mid = dts[len(dts) // 2]
    es = []
    for lab in labels:
        e = data["energy"].get(lab, {}).get(mid)
        if e is not None:
            es.append({"label": lab, "x": e[0], "y": e[1], "style": styles.get(lab)})
    F.energy_figure(stage / "figures" / "energy_vs_time.png", es,
                    title=f"Energy conservation of the integrators at dt = {mid:.4g} s", legend_title=LEGEND_TITLE)
    report.figure("figures/energy_vs_time.png",
                  f"Relative energy error against time at dt = {mid:.4g} (symplectic methods stay bounded)")

    rows = [{"method": r["integrator"], "h_omega": r["h_omega"], "stable": r["stable"],
             "bound": None} for r in recs if r.get("h_omega")]
    if rows:
        from ..integrators import oscillator_bound

        bounds, never = {}, []
        for spec in study.integrators:
            lab = spec.label
            # the scenes are undamped: methods whose region misses the imaginary axis have no limit
            bounds[lab] = oscillator_bound(spec.build())
            if bounds[lab] is None:
                never.append(lab)
        for r in rows:
            r["bound"] = bounds.get(r["method"])
        F.stability_map_figure(stage / "figures" / "stability.png", rows,
                               title="Which runs survived")
        report.figure("figures/stability.png", "Survived (o) and unstable (x) runs against dt * omega_max; "
                      "black bars: the method's theoretical limit"
                      + (f" ({', '.join(never)}: none, unstable at every dt on an undamped scene; "
                         "the energy grows slowly at small dt)" if never else ""))

    report.heading("Runs")
    cols = ["integrator", "dt", "steps", "stable", "error_end", "error_max", "energy_drift", "energy_drift_max",
            "wall_time", "h_omega", "pareto"]
    report.table(cols, [[r.get(c) for c in cols] for r in recs],
                 caption="errors: 2-norm of all position errors [length]; energy drift relative to the energy scale")


#: The lines ``femkit study`` prints: one per fitted order.
summary = fit_lines
