"""Report of a ``contact_penalty`` study: maximum penetration against the penalty stiffness."""

from __future__ import annotations

__all__ = ["build", "summary"]


def _figure(path, title: str, records) -> None:
    from ...io.figures import new_figure, save_figure

    fig = new_figure(6.0, 4.2)
    ax = fig.subplots()
    pen = [r for r in records if r["method"] == "penalty"]
    ax.loglog([r["stiffness"] for r in pen], [max(r["max_penetration"], 1e-16) for r in pen],
              marker="o", label="penalty ground: max penetration")
    bar = [r for r in records if r["method"] == "barrier"]
    for r in bar:
        ax.axhline(max(r["min_height"], 1e-16), color="black", ls="--",
                   label=f"barrier: smallest gap {r['min_height']:.2e} (never penetrates)")
    ax.set_xlabel("penalty stiffness k_c")
    ax.set_ylabel("length")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)


def build(report, study, result, data, stage) -> None:
    report.paragraph("A cloth dropped on the ground, integrated by newton with the same step: "
                     "the largest penetration of penalty contact for each stiffness, and the "
                     "smallest gap of barrier contact (IPC), which never penetrates.")
    _figure(stage / "figures/contact_penalty.png", study.title, result.records)
    report.figure("figures/contact_penalty.png", "Maximum penetration against penalty stiffness; "
                                                 "barrier contact's smallest gap (dashed)")
    cols = ["method", "stiffness", "max_penetration", "min_height", "newton_iterations"]
    report.table(cols, [[r[c] for c in cols] for r in result.records])


def summary(result) -> list[str]:
    out = []
    for r in result.records:
        out.append(f"{r['method']} (stiffness {r['stiffness']:.3g}): max penetration "
                   f"{r['max_penetration']:.3e}, lowest point {r['min_height']:.3e}")
    return out
