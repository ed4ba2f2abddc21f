"""Report of a ``stability`` study: the verdict table, stability boundaries, a stability map."""

from __future__ import annotations

from .. import figures as F
from ..report import fmt
from ..summary import fit_lines


def _cell(r) -> str:
    if r.get("survived") is None:
        return "-"
    mark = "ok" if r["survived"] else "FAIL"
    parts = [mark]
    if r.get("iterations") is not None:
        parts.append(f"{r['iterations']} it")
    if r.get("relative_residual") is not None:
        parts.append(f"res {fmt(r['relative_residual'])}")
    if r.get("error") is not None:
        parts.append(f"err {fmt(r['error'])}")
    if r.get("time") is not None:
        parts.append(f"{fmt(r['time'])} s")
    if not r["survived"] or r.get("outcome") not in ("converged", "completed", None):
        parts.append(f"({r.get('outcome')})")
    return ", ".join(parts)


PARAMETER_NAMES = {"poisson_contrast": "kappa contrast", "poisson_anisotropic": "aspect ratio",
                   "poisson_scaled": "domain scale s", "poisson_degenerate": "sliver relative area eps",
                   "poisson_fine": "unknowns"}


def build(report, study, result, data, stage) -> None:
    recs = result.records
    static = [r for r in recs if r["type"] != "dynamics_stiffness"]
    report.heading("Verdicts: method x case")
    report.paragraph("Each cell: survived (ok: converged to the requested true residual / completed; for the "
                     "Neumann and Jacobi cases: the failure was reported cleanly), iterations, attained true relative "
                     "residual ||b - Ax|| / ||b||, error (relative to the direct solution; for scaled domains the "
                     "discretisation error relative to ||u||, which must not depend on the scale), wall time.")
    methods = list(dict.fromkeys(r["method"] for r in static))
    cases = list(dict.fromkeys((r["case"], str(r["value"])) for r in static))
    rows = []
    for case, value in cases:
        cells = []
        for m in methods:
            match = [r for r in static if r["case"] == case and str(r["value"]) == value and r["method"] == m]
            cells.append(_cell(match[0]) if match else "")
        dofs = next(r.get("dofs") for r in static if r["case"] == case and str(r["value"]) == value)
        rows.append([case, value, dofs] + cells)
    if rows:
        report.table(["case", "parameter", "unknowns"] + methods, rows)
    drift = [r for r in static if r["type"] == "cg_residual_drift"]
    if drift:
        report.heading("CG: recursive against true residual")
        report.paragraph("CG's recursively updated residual keeps falling to round-off while the true residual "
                         "||b - A x|| stalls near eps ||A|| ||x|| / ||b||; femkit's `converged` follows the true one.")
        report.table(["condition number", "iterations", "recursive relres", "true relres", "converged flag", "reason"],
                     [[r["value"], r["iterations"], r["recursive_residual"], r["relative_residual"],
                       r["converged_flag"], r["outcome"]] for r in drift])
    dyn = [r for r in recs if r["type"] == "dynamics_stiffness"]
    if dyn:
        b = result.tables.get("stability_boundaries", [])
        report.heading("Explicit integrators: measured stability boundary")
        report.paragraph("Each explicit integrator run at dt = factor x bound / omega_max (omega_max by power "
                         "iteration on M^-1 K) on a two-spring chain; a run survives when its energy does not grow "
                         "by more than 10x between its first and last third and never exceeds 1000 x E0. Theory "
                         "(h omega_max): 2 for symplectic Euler / Verlet / leapfrog / central difference, "
                         "2 sqrt 2 = 2.83 for RK4, 0 (never stable on an undamped oscillator) for explicit Euler, "
                         "Heun and midpoint.")
        report.table(["springs / masses", "method", "largest stable h*omega", "smallest unstable h*omega",
                      "theory", "consistent"],
                     [[x["value"], x["method"], x["largest_stable_h_omega"], x["smallest_unstable_h_omega"],
                       x["theory_h_omega"], x["consistent_with_theory"]] for x in b])
        methods_d = list(dict.fromkeys(r["method"] for r in dyn))
        rows = [{"method": r["method"], "h_omega": r["h_omega"], "stable": r["survived"],
                 "bound": r["bound"] if r["bound"] > 0 else None} for r in dyn]
        F.stability_map_figure(stage / "figures" / "stability_map.png", rows,
                               title="Explicit integrators across the critical step")
        report.figure("figures/stability_map.png",
                      f"Survived (o) / unstable (x) runs of {', '.join(methods_d)} against dt * omega_max over "
                      "every stiffness and mass ratio; black bars: theoretical limits")
    iters = [r for r in static if r.get("iterations") is not None and r["type"].startswith("poisson_")
             and r["type"] not in ("poisson_neumann",)]
    if iters:
        panels = []
        for case in dict.fromkeys(r["case"] for r in iters):
            series = []
            for m in methods:
                rs = [r for r in iters if r["case"] == case and r["method"] == m]
                try:
                    xs = [float(r["value"]) for r in rs]
                except (TypeError, ValueError):
                    continue
                if len(xs) > 1:
                    series.append({"label": m, "x": xs, "y": [r["iterations"] for r in rs],
                                   "ok": [bool(r["survived"]) for r in rs]})
            if series:
                kind = next(r["type"] for r in iters if r["case"] == case)
                panels.append({"title": case, "xlabel": PARAMETER_NAMES.get(kind, "parameter"), "series": series})
        if panels:
            F.panels_figure(stage / "figures" / "iterations_vs_parameter.png", panels,
                            title="Iterations against each stress parameter", ylabel="iterations")
            report.figure("figures/iterations_vs_parameter.png",
                          "Iterations against each case's stress parameter (one panel per case); ringed points "
                          "did not reach the requested true residual")


#: The lines ``femkit study`` prints: one per fitted rate.
summary = fit_lines
