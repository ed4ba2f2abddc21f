"""Report of a ``cloth_work_precision`` study: error per frame against time per frame, energy."""

from __future__ import annotations

import numpy as np

__all__ = ["build", "summary", "family_styles"]


_COLOURS = ("tab:blue", "tab:green", "tab:red", "tab:purple", "tab:orange", "tab:brown",
            "tab:pink", "tab:olive", "tab:cyan", "tab:gray")


_MARKERS = ("o", "s", "D", "^", "v", "P", "X", "*", "<", ">")


def family_styles() -> dict:
    """family -> (colour, marker), in the order of :data:`~femkit.dynamics.work_precision.FAMILIES`
    (a family added there gets the next style)."""
    from ...dynamics.work_precision import FAMILIES

    return {fam: (_COLOURS[i % len(_COLOURS)], _MARKERS[i % len(_MARKERS)])
            for i, fam in enumerate(FAMILIES)}


def _figure(path, title: str, recs: list, energy: dict) -> None:
    """Three panels: solve error and trajectory error per frame against time per frame (one line
    per family, Pareto front as a band), energy history."""
    from ...dynamics.work_precision import FAMILIES
    from ...io.figures import new_figure, save_figure

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


def build(report, study, result, data, stage) -> None:
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


def summary(result) -> list[str]:
    lines = []
    for scene in dict.fromkeys(r["scene"] for r in result.records):
        rows = [r for r in result.records if r["scene"] == scene]
        for key, what in (("pareto_solve", "solve"), ("pareto_trajectory", "trajectory")):
            front = [r["label"] for r in sorted(rows, key=lambda r: r["time_per_frame"]) if r[key]]
            lines.append(f"{scene}: Pareto front ({what} error): {', '.join(front)}")
    return lines
