"""The report of an ``element_work_precision`` study: runs, rates, crossover, figures."""

from __future__ import annotations

__all__ = ["build", "summary", "crossover_line"]

_NAMES = {"L2": "L2", "H1_semi": "H1 seminorm", "corner": "relative displacement"}
_COLUMNS = {"corner": ["displacement", "corner"], None: ["nnz", "iterations", "L2", "H1_semi"]}


def crossover_line(c: dict) -> str:
    """One sentence: from which error ``c["high"]`` is cheaper than ``c["low"]`` (a
    :func:`~.run.crossover` result), or that it is everywhere, or nowhere, in the range measured.

    >>> crossover_line({"low": "P1", "high": "P2", "norm": "L2", "cost": "t", "error": None,
    ...                 "everywhere": False, "range": [1e-4, 1e-2]})
    'P2 is not cheaper in run time than P1 at any L2 error measured (no crossover in 1.00e-04 .. 1.00e-02)'
    """
    what = "run time" if c["cost"] == "t" else "unknowns"
    norm = _NAMES[c["norm"]]
    if c["range"] is None:
        return _apart_line(c, what, norm)
    lo, hi = c["range"]
    if c["everywhere"]:
        return (f"{c['high']} is cheaper in {what} than {c['low']} at every {norm} error measured "
                f"(no crossover in {lo:.2e} .. {hi:.2e})")
    if c["error"] is None:
        return (f"{c['high']} is not cheaper in {what} than {c['low']} at any {norm} error measured "
                f"(no crossover in {lo:.2e} .. {hi:.2e})")
    return (f"{c['high']} is cheaper in {what} than {c['low']} for {norm} errors below "
            f"{c['error']:.2e} (errors compared over {lo:.2e} .. {hi:.2e})")


def _apart_line(c: dict, what: str, norm: str) -> str:
    """The sentence for two error ranges that do not overlap (no crossover can be measured)."""
    a = c.get("apart")
    head = f"{c['high']} vs {c['low']} ({norm}): the error ranges do not overlap (no crossover measured)"
    if not a:
        return head
    unit = " s" if c["cost"] == "t" else " unknowns"
    (hl, hh), (ll, lh) = a["high_errors"], a["low_errors"]
    if hh < ll:
        verdict = "less" if a["high_min_cost"] < a["low_max_cost"] else "more"
        return (f"{head}; every {c['high']} run is more accurate than every {c['low']} run (errors <= "
                f"{hh:.2e} against >= {ll:.2e}), and its cheapest costs {verdict} {what} "
                f"({a['high_min_cost']:.3g}{unit}) than {c['low']}'s finest ({a['low_max_cost']:.3g}{unit})")
    return (f"{head}; every {c['low']} run is more accurate than every {c['high']} run (errors <= "
            f"{lh:.2e} against >= {hl:.2e})")


def build(report, study, result, data, stage) -> None:
    from .. import figures as F

    recs = result.records
    series = list(dict.fromkeys(r["element"] for r in recs))
    norms = [n for n in _NAMES if any(r.get(n) is not None for r in recs)]
    solid = "corner" in norms
    report.heading("Crossover")
    report.paragraph("At equal error, which series costs less run time, interpolated log-log between "
                     "the levels. Uniform runs: " + ("building the body and its loads + the static solve"
                                                     if solid else "assembly + boundary + solve")
                     + " on the level, minimum over repeats; adaptive runs: the loop's wall time up to "
                     "the level (every coarser level's solve, estimate and refinement included).")
    for c in result.tables.get("crossover", []):
        report.paragraph(crossover_line(c))
    report.heading("Fitted rates against unknowns")
    report.table(["series", "norm", "rate vs dofs", "R²"],
                 [[f["element"], _NAMES[f["norm"]], f["rate_vs_dofs"], f["fit"].r2]
                  for f in data.get("fits", [])])
    fits = {(f["element"], f["norm"]): f["fit"] for f in data.get("fits", [])}
    for name, x, xlabel in (("error_vs_dofs", "dofs", "unknowns"),
                            ("error_vs_time", "t", "run time [s]")):
        lines = []
        for e in series:
            for n in norms:
                rows = [r for r in recs if r["element"] == e and r.get(n) is not None]
                if rows:
                    lines.append({"label": f"{_NAMES[n]}, {e}", "x": [r[x] for r in rows],
                                  "y": [r[n] for r in rows],
                                  "fit": fits.get((e, n)) if x == "dofs" else None})
        F.loglog_figure(stage / "figures" / f"{name}.png", lines, title=f"Error against {xlabel}",
                        xlabel=xlabel, ylabel="error")
        report.figure(f"figures/{name}.png", f"errors of each series against {xlabel}")
    report.heading("Runs")
    cols = ["element", "level", "cells", "dofs", "t"] + _COLUMNS["corner" if solid else None]
    report.table(cols, [[r.get(c) for c in cols] for r in recs])


def summary(result) -> list[str]:
    return [crossover_line(c) for c in result.tables.get("crossover", [])]
