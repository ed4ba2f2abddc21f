"""The report of an ``element_work_precision`` study: runs, rates, crossover, figures."""

from __future__ import annotations

__all__ = ["build", "summary"]

_NAMES = {"L2": "L2", "H1_semi": "H1 seminorm"}


def _crossover_line(c: dict) -> str:
    what = "run time" if c["cost"] == "t" else "unknowns"
    norm = _NAMES[c["norm"]]
    if c["range"] is None:
        return f"{c['high']} vs {c['low']} ({norm}): the two error ranges do not overlap"
    span = f"(errors compared over {c['range'][0]:.2e} .. {c['range'][1]:.2e})"
    if c["everywhere"]:
        return f"{c['high']} is cheaper in {what} than {c['low']} at every {norm} error measured {span}"
    if c["error"] is None:
        return f"{c['high']} is not cheaper in {what} than {c['low']} at the {norm} errors measured {span}"
    return (f"{c['high']} is cheaper in {what} than {c['low']} for {norm} errors below "
            f"{c['error']:.2e} {span}")


def build(report, study, result, data, stage) -> None:
    from .. import figures as F

    recs = result.records
    elements = list(dict.fromkeys(r["element"] for r in recs))
    report.heading("Crossover")
    report.paragraph("At equal error, which element costs less run time (assembly + boundary + solve, "
                     "minimum over repeats), interpolated log-log between the levels.")
    for c in result.tables.get("crossover", []):
        report.paragraph(_crossover_line(c))
    report.heading("Fitted rates against unknowns")
    report.table(["element", "norm", "rate vs dofs", "R²"],
                 [[f["element"], _NAMES[f["norm"]], f["rate_vs_dofs"], f["fit"].r2]
                  for f in data.get("fits", [])])
    for name, x, xlabel in (("error_vs_dofs", "dofs", "free unknowns"),
                            ("error_vs_time", "t", "run time: assembly + boundary + solve [s]")):
        series = [{"label": f"{_NAMES[n]}, {e}", "x": [r[x] for r in recs if r["element"] == e],
                   "y": [r[n] for r in recs if r["element"] == e]} for e in elements for n in _NAMES]
        F.loglog_figure(stage / "figures" / f"{name}.png", series, title=f"Error against {xlabel}",
                        xlabel=xlabel, ylabel="error norm")
        report.figure(f"figures/{name}.png", f"L2 and H1 errors of each element against {xlabel}")
    report.heading("Runs")
    cols = ["element", "level", "cells", "dofs", "nnz", "iterations", "t", "L2", "H1_semi"]
    report.table(cols, [[r[c] for c in cols] for r in recs])


def summary(result) -> list[str]:
    return [_crossover_line(c) for c in result.tables.get("crossover", [])]
