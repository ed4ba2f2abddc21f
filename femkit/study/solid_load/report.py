"""Report of a ``solid_load`` study: deflection against load per material, with the theory."""

from __future__ import annotations

import numpy as np

from .run import elastica_deflection

__all__ = ["build", "summary"]


def _figure(path, title: str, records) -> None:
    from ...io.figures import new_figure, save_figure

    fig = new_figure(9.5, 4.2)
    ax1, ax2 = fig.subplots(1, 2)
    alphas = np.linspace(1e-3, max(r["alpha"] for r in records), 60)
    ax2.plot(alphas, [elastica_deflection(a) / (a / 3.0) for a in alphas], color="black", lw=2,
             label="elastica (inextensible beam)")
    top = max(r["alpha"] for r in records)
    styles = ("-", "--", "-.", ":")
    for i, name in enumerate(dict.fromkeys(r["material"] for r in records)):
        rows = [r for r in records if r["material"] == name]
        if not rows:  # no equilibrium at the first load step: nothing to draw (see the notes)
            continue
        a = [0.0] + [r["alpha"] for r in rows]
        line, = ax1.plot(a, [0.0] + [abs(r["tip_deflection"]) for r in rows], marker="o", ms=3,
                         ls=styles[i % 4], label=name)
        if rows[0]["ratio_to_linear"] is not None:
            ax2.plot([r["alpha"] for r in rows], [r["ratio_to_linear"] for r in rows], marker="o",
                     ms=3, ls=styles[i % 4], color=line.get_color(), label=name)
        if rows[-1]["alpha"] < 0.999 * top:   # no equilibrium at the next load step
            last = rows[-1]
            for ax, y in ((ax1, abs(last["tip_deflection"])), (ax2, last["ratio_to_linear"])):
                if y is not None:
                    ax.plot([last["alpha"]], [y], marker="X", ms=11, color=line.get_color())
                    ax.annotate(f"{name}: no equilibrium\nbeyond alpha = {last['alpha']:.2g}",
                                (last["alpha"], y), xytext=(12, 14), textcoords="offset points",
                                fontsize=7, color=line.get_color(),
                                arrowprops={"arrowstyle": "-", "color": line.get_color()})
    rows = [r for r in records if r["material"] == records[0]["material"]]
    ax1.plot([0.0] + [r["alpha"] for r in rows], [0.0] + [r["beam_theory"] for r in rows],
             color="black", ls="--", lw=1, label="linear beam theory P L^3 / 3EI")
    ax1.set_xlabel("load parameter alpha = P L^2 / (E I)")
    ax1.set_ylabel("tip deflection along the load")
    ax1.set_title("tip deflection", fontsize=10)
    ax2.set_xlabel("load parameter alpha = P L^2 / (E I)")
    ax2.set_ylabel("deflection / linear material's deflection")
    ax2.set_title("geometric and material nonlinearity", fontsize=10)
    for ax, where in ((ax1, "upper left"), (ax2, "lower left")):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc=where)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    save_figure(fig, path)


def build(report, study, result, data, stage) -> None:
    report.paragraph("Tip deflection (mean displacement of the loaded face along the load) of a "
                     "clamped beam under a dead tip traction growing in equal load steps, one "
                     "curve per material with the same E, nu. Right: each material's deflection "
                     "divided by the linear material's on the same mesh, against the elastica's "
                     "ratio to linear beam theory.")
    _figure(stage / "figures/solid_load.png", study.title, result.records)
    report.figure("figures/solid_load.png", "Tip deflection against the load parameter, per "
                                            "material; the elastica and linear beam theory")
    cols = ["material", "load_factor", "alpha", "tip_deflection", "ratio_to_linear",
            "elastica_ratio", "iterations", "volume_change"]
    report.table(cols, [[r[c] for c in cols] for r in result.records])


def summary(result) -> list[str]:
    out = []
    for name in dict.fromkeys(r["material"] for r in result.records):
        r = [x for x in result.records if x["material"] == name][-1]
        ratio = "" if r["ratio_to_linear"] is None else \
            f", {r['ratio_to_linear']:.3f} x linear (elastica {r['elastica_ratio']:.3f})"
        out.append(f"{name}: tip deflection {r['tip_deflection']:.4g} at alpha "
                   f"{r['alpha']:.3g}{ratio}")
    return out
