"""Report of an ``adaptive`` study: the final meshes, effectivity, error against unknowns and
time, the printed rates."""

from __future__ import annotations

import numpy as np

__all__ = ["build", "summary"]


#: above this many triangles the full-mesh panel shows the local mesh size, not the edges
_DRAWN_EDGES_MAX = 20_000


def _mesh_figure(path, mesh, indicators, title: str) -> str:
    from matplotlib.colors import LogNorm
    from matplotlib.tri import Triangulation

    from ...io.figures import new_figure, save_figure

    fig = new_figure(16, 5, layout="constrained")
    tri = Triangulation(mesh.points[:, 0], mesh.points[:, 1], mesh.triangles)
    ax1, ax3, ax2 = fig.add_subplot(1, 3, 1), fig.add_subplot(1, 3, 2), fig.add_subplot(1, 3, 3)
    areas = mesh.areas()
    if mesh.n_triangles <= _DRAWN_EDGES_MAX:
        ax1.triplot(tri, color="k", linewidth=0.3 if mesh.n_triangles < 5000 else 0.1)
        ax1.set_title(f"{title}: {mesh.n_triangles} triangles", fontsize=9)
    else:  # edges would merge into a grey moire: show the local mesh size instead
        h = np.sqrt(2.0 * areas)
        art1 = ax1.tripcolor(tri, facecolors=h, cmap="viridis_r", norm=LogNorm(h.min(), h.max()))
        fig.colorbar(art1, ax=ax1, label="local mesh size h_T (log scale)")
        ax1.set_title(f"{title}: {mesh.n_triangles} triangles (too many to draw: size shown)",
                      fontsize=9)
    # zoom on the finest triangle: the grading of the refinement
    k = int(np.argmin(areas))
    c, r = mesh.centroids()[k], 40.0 * np.sqrt(areas[k])
    ax3.triplot(tri, color="k", linewidth=0.4)
    ax3.set_xlim(c[0] - r, c[0] + r)
    ax3.set_ylim(c[1] - r, c[1] + r)
    ax3.set_title(f"zoom x{np.ptp(mesh.points[:, 0]) / (2 * r):.0f} on the finest triangle", fontsize=9)
    eta = np.asarray(indicators, dtype=float)
    lo = eta[eta > 0].min() if (eta > 0).any() else 1e-300
    art = ax2.tripcolor(tri, facecolors=np.maximum(eta, lo), cmap="magma",
                        norm=LogNorm(vmin=max(lo, eta.max() * 1e-6), vmax=max(eta.max(), lo * 10)))
    fig.colorbar(art, ax=ax2, label="indicator eta_T (log scale)")
    ax2.set_title("element error indicators: equidistributed when adapted", fontsize=9)
    for ax in (ax1, ax2, ax3):
        ax.set_aspect("equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
    save_figure(fig, path)
    return str(path)


def _effectivity_figure(path, series) -> str:
    from ...io.figures import new_figure, save_figure

    fig = new_figure(7, 4.5, layout="constrained")
    ax = fig.add_subplot()
    for s in series:
        ax.semilogx(s["x"], s["y"], marker="o", markersize=4, label=s["label"])
    ax.axhline(1.0, color="k", linewidth=0.8)
    ax.set_xlabel("degrees of freedom")
    ax.set_ylabel("effectivity = estimate / true energy error")
    ax.set_title("Effectivity per level (1 = exact estimate)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save_figure(fig, path)
    return str(path)


def build(report, study, result, data, stage) -> None:
    from .. import figures as F

    recs = result.records
    measured = data["measured"]
    labels = list(dict.fromkeys(r["run"] for r in recs))
    ylab = "true energy-norm error" if measured == "error" else "estimated energy-norm error"
    report.heading("Outcome")
    cols = ["run", "levels", "dofs", "estimate", "error", "total_time", "target_met", "stop_reason"]
    report.table(cols, [[o.get(c) for c in cols] for o in result.tables["outcome"]],
                 caption="last level of each run; total_time = wall time from the first solve to the last "
                         "estimate (true-error evaluation excluded), seconds")
    report.heading("Fitted rates")
    report.paragraph(f"Slope of log({measured}) against log(dofs) and against log(run time), over the levels "
                     f"with at least {study.spec.fit_min_dofs} dofs. For P1 the optimal energy rate is "
                     "dofs^-1/2; a corner singularity r^a limits uniform refinement to dofs^-a/2 "
                     "(1/3 on the L-shape).")
    cols = ["run", "error", "against", "slope", "r2", "n"]
    report.table(cols, [[f.get(c) for c in cols] for f in result.fits])
    fit_of = {(f["run"], f["against"]): f["fit"] for f in result.fits}

    def series(key):
        return [{"label": lab, "x": [r[key] for r in recs if r["run"] == lab],
                 "y": [r["measured"] for r in recs if r["run"] == lab],
                 "fit": fit_of.get((lab, "dofs" if key == "dofs" else "time"))} for lab in labels]

    F.loglog_figure(stage / "figures" / "error_vs_dofs.png", series("dofs"), title=f"{ylab} against dofs",
                    xlabel="degrees of freedom", ylabel=ylab, triangle=-0.5)
    report.figure("figures/error_vs_dofs.png", f"{ylab} against dofs, uniform and adaptive (fitted rates in the legend)")
    F.work_precision_figure(stage / "figures" / "error_vs_time.png",
                            [{k: v for k, v in s.items() if k != "fit"} for s in series("elapsed")],
                            title=f"{ylab} against run time", xlabel="wall time since the start of the run [s]",
                            ylabel=ylab)
    report.figure("figures/error_vs_time.png", "Work-precision: error against cumulative run time, both refinements")
    adaptive = [lab for lab in labels if lab != "uniform"][0]
    mesh, eta = data["meshes"][adaptive]
    _mesh_figure(stage / "figures" / "final_mesh.png", mesh, eta, f"final mesh, {adaptive}")
    report.figure("figures/final_mesh.png", f"Final mesh of {adaptive} and its element indicators")
    if measured == "error":
        _effectivity_figure(stage / "figures" / "effectivity.png",
                            [{"label": lab, "x": [r["dofs"] for r in recs if r["run"] == lab],
                              "y": [r["effectivity"] for r in recs if r["run"] == lab]} for lab in labels])
        report.figure("figures/effectivity.png", "Effectivity of the estimate per level")
    report.heading("Levels")
    cols = ["run", "level", "dofs", "n_elements", "estimate", "error", "effectivity", "iterations", "marked",
            "solve_time", "estimate_time", "refine_time", "elapsed"]
    report.table(cols, [[r.get(c) for c in cols] for r in recs], caption="times in seconds")


def summary(result) -> list[str]:
    lines = [f"{o['run']}: {o['levels']} levels, {o['dofs']} dofs, estimate {o['estimate']:.3e}"
             + (f", error {o['error']:.3e}" if o["error"] is not None else "")
             + f", {o['total_time']:.2f} s, stopped by {o['stop_reason']}" for o in result.tables["outcome"]]
    lines += [f"rate {f['run']} / {f['error']} vs {f['against']}: {f['slope']:.3f}" for f in result.fits]
    return lines
