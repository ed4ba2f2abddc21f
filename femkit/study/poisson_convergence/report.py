"""Report of a ``poisson_convergence`` study: tables of runs and rates, four figures."""

from __future__ import annotations

import numpy as np

from .. import figures as F
from ..pareto import pareto_front
from ..summary import r2_text

THEORY = {"L2": 2.0, "H1_semi": 1.0}
NORM_ORDER = {"L2": 0, "H1_semi": 1, "max_nodal": 2}


def _lines(records):
    return list(dict.fromkeys((r["source"], r["solver"], r["quadrature"]) for r in records))


def _label(key, many_rules):
    src, solver, rule = key
    if src != "femkit":
        return solver
    return f"{solver} / {rule}" if many_rules else solver


RULE_LINES = ("-", ":", "-.", (0, (5, 1, 1, 1, 1, 1)))


def line_styles(recs, rules) -> dict:
    """(source, solver, rule) -> style: solver = colour + marker, rule = line style, peer black dashed."""
    book = F.StyleBook({rule: RULE_LINES[i % len(RULE_LINES)] for i, rule in enumerate(rules)})
    out = {}
    for key in _lines(recs):
        src, solver, rule = key
        out[key] = dict(F.REFERENCE_STYLE) if src != "femkit" else book(solver, rule)
    return out


def _rule_legend(rules) -> str | None:
    names = {"-": "solid", ":": "dotted", "-.": "dash-dot"}
    if len(rules) < 2:
        return None
    return "line style = quadrature rule\n" + ", ".join(
        f"{names.get(RULE_LINES[i], 'dash-dot-dot')}: {r}" for i, r in enumerate(rules)) + "\nblack dashed: scikit-fem"


def grouped_rate_rows(fits) -> list[list]:
    """One table row per (source, quadrature, norm) and group of solvers with the same displayed fit.

    Fits are equal when rate, its standard error, R² (each to :func:`~femkit.study.report.fmt`'s
    4 significant digits) and the number of levels agree; a group holding every femkit solver
    reads "all solvers".
    """
    from ..report import fmt

    solvers = list(dict.fromkeys(f["solver"] for f in fits if f["source"] == "femkit"))
    groups: dict = {}
    for f in fits:
        shown = (fmt(f["slope"]), fmt(f["slope_stderr"]), fmt(f["r2"]), f["n"])
        groups.setdefault((f["source"], f["quadrature"], f["norm"], shown), []).append(f)
    rows = []
    for (src, rule, norm, _), fs in groups.items():
        names = [f["solver"] for f in fs]
        if src != "femkit":
            who = names[0]
        elif len(solvers) > 1 and names == solvers:
            who = "all solvers"
        else:
            who = ", ".join(names)
        th = THEORY.get(norm)
        f = fs[0]
        rows.append(((src != "femkit", rule, NORM_ORDER.get(norm, 9)),
                     [who, rule, norm, f["slope"], f["slope_stderr"], f["r2"], f["n"], "-" if th is None else th]))
    return [r for _, r in sorted(rows, key=lambda kr: kr[0])]


def build(report, study, result, data, stage) -> None:
    recs = result.records
    femkit_recs = [r for r in recs if r["source"] == "femkit"]
    rules = list(dict.fromkeys(r["quadrature"] for r in femkit_recs))
    many = len(rules) > 1
    styles = line_styles(recs, rules)
    norm_book = F.StyleBook({rule: RULE_LINES[i % len(RULE_LINES)] for i, rule in enumerate(rules)})
    lines = _lines(recs)
    fits = {(f["source"], f["solver"], f["quadrature"], f["norm"]): f for f in result.fits}

    report.heading("Fitted convergence rates")
    report.paragraph("Least-squares slope of log(error) against log(h) over all levels (h = longest edge); "
                     "theory for P1 on a smooth solution: L2 2, H1 seminorm 1. R² near 1 means the levels lie on "
                     "one line (asymptotic regime); the standard error is that of the slope. Solvers whose fits "
                     "agree to the displayed precision share one row (every solver stops far below the "
                     "discretisation error, so they see the same errors); the per-solver fits are in fits.csv.")
    report.table(["solvers", "quadrature", "norm", "rate", "std. error", "R²", "levels", "theory"],
                 grouped_rate_rows(result.fits))

    # first femkit solver per rule carries the discretisation error; reference drawn dashed
    first_solver = femkit_recs[0]["solver"] if femkit_recs else None
    series_h, series_dofs = [], []
    for key in lines:
        src, solver, rule = key
        if src == "femkit" and solver != first_solver:
            continue
        rows_k = [r for r in recs if (r["source"], r["solver"], r["quadrature"]) == key]
        for norm, name in (("L2", "L2"), ("H1_semi", "H1 seminorm")):
            y = [np.nan if r[norm] is None else r[norm] for r in rows_k]
            lab = f"{name} ({'scikit-fem' if src != 'femkit' else 'femkit'}{', ' + rule if many and src == 'femkit' else ''})"
            st = dict(F.REFERENCE_STYLE, marker="x" if norm == "L2" else "+") if src != "femkit" \
                else norm_book(norm, rule)
            base = {"label": lab, "reference": src != "femkit", "style": st}
            series_h.append({**base, "x": [r["h"] for r in rows_k], "y": y, "fit": fits.get((*key, norm), {}).get("fit")})
            series_dofs.append({**base, "x": [r["dofs"] for r in rows_k], "y": y})
    F.loglog_figure(stage / "figures" / "error_vs_h.png", series_h,
                    title="P1 convergence: L2 and H1 errors vs mesh size",
                    xlabel="h, longest edge [length unit of the mesh]", ylabel="error norm (L2, H1 seminorm)",
                    triangle=2, invert_x=True, note="thin dotted: least-squares fit; triangle: slope 2")
    report.heading("Figures")
    report.figure("figures/error_vs_h.png", "Error against mesh size h (finer to the right), fitted rates in the legend")
    F.loglog_figure(stage / "figures" / "error_vs_dofs.png", series_dofs,
                    title="P1 convergence: L2 and H1 errors vs unknowns",
                    xlabel="degrees of freedom (free unknowns)", ylabel="error norm (L2, H1 seminorm)", triangle=-1,
                    note="triangle: slope -1 (L2 ~ h^2 ~ 1/dofs in 2D)")
    report.figure("figures/error_vs_dofs.png", "Error against the number of unknowns")
    _solution_figure(report, study, data, stage, rules[0])

    it_series = []
    for key in lines:
        rows_k = [r for r in recs if (r["source"], r["solver"], r["quadrature"]) == key]
        if key[0] == "femkit" and (rows_k[0]["method"] == "direct" or (many and key[2] != rules[0])):
            continue
        it_series.append({"label": f"{_label(key, False)}, fixed rtol", "reference": key[0] != "femkit",
                          "x": [r["dofs"] for r in rows_k], "y": [r["iterations"] for r in rows_k],
                          "style": {**styles[key], "linestyle": "-"} if key[0] == "femkit" else styles[key]})
    for s in dict.fromkeys(n["solver"] for n in data.get("nested", [])):
        rows_n = [n for n in data["nested"] if n["solver"] == s]
        key = next(k for k in lines if k[0] == "femkit" and k[1] == s)
        it_series.append({"label": f"{s}, nested, stop at discretisation error",
                          "x": [n["dofs"] for n in rows_n], "y": [n["iterations_nested"] for n in rows_n],
                          "style": {**styles[key], "linestyle": ":", "markerfacecolor": "none"}})
    if it_series:
        F.loglog_figure(stage / "figures" / "iterations_vs_dofs.png", it_series,
                        title="Solver cost: iterations vs unknowns (fixed rtol and nested)",
                        xlabel="degrees of freedom (free unknowns)",
                        ylabel="iterations to the stopping rule",
                        legend_title="solid: fixed rtol from zero; dotted, open: nested" if data.get("nested") else None)
        report.figure("figures/iterations_vs_dofs.png", "Iterations against unknowns (AMG flat, CG ~ dofs^0.5)")

    wp, t_all, e_all = [], [], []
    for key in lines:
        rows_k = [r for r in recs if (r["source"], r["solver"], r["quadrature"]) == key]
        t = [r["t_total"] for r in rows_k]
        e = [r["L2"] for r in rows_k]
        wp.append({"label": _label(key, many), "reference": key[0] != "femkit", "x": t, "y": e,
                   "style": styles[key]})
        t_all += t
        e_all += e
    front = pareto_front(t_all, e_all)
    F.work_precision_figure(stage / "figures" / "work_precision.png", wp,
                            front=[(t_all[i], e_all[i]) for i in front],
                            title="Work-precision of the solvers: L2 error vs run time",
                            xlabel="run time: assembly + boundary + solve [s] (min over repeats)",
                            ylabel="L2 error ||u - u_h||", legend_title=_rule_legend(rules))
    report.figure("figures/work_precision.png",
                  "Work-precision: L2 error against run time, one line per solver; the Pareto front highlighted")
    pareto_ids = set(front.tolist())
    for i, r in enumerate(recs):
        r["pareto"] = i in pareto_ids

    report.heading("Runs")
    cols = ["source", "solver", "quadrature", "level", "h", "dofs", "nnz", "L2", "H1_semi", "max_nodal",
            "iterations", "relative_residual", "t_mesh", "t_assembly", "t_boundary", "t_solve", "t_errors",
            "pareto"]
    report.table(cols, [[r.get(c) for c in cols] for r in recs],
                 caption="times in seconds (minimum over repeats); relative_residual = ||b - Ax|| / ||b||")

    nested = data.get("nested") or []
    if nested:
        frac = nested[0]["fraction"]
        report.heading("Solving to the discretisation error")
        report.paragraph(
            f"Nested iteration ((P)CG): each level starts from the previous level's solution interpolated to the "
            f"refined mesh (new midpoint nodes take the average of their edge's end values) and stops at the first "
            f"iterate whose Gauss-Radau upper bound of the algebraic error ||u_l - x_m||_A (Meurant-Tichy "
            f"recurrence from the per-iteration alpha_k and r_k^T z_k, mu = lambda_0 (h_l/h_0)^2 / 2 with lambda_0 "
            f"the smallest Ritz value of M^-1 A on level 0) is {frac:g} x the estimated discretisation error "
            f"eta_m = ||x_m - x_0||_A / sqrt 3 (Galerkin orthogonality on nested spaces, H1 rate 1); the "
            f"Hestenes-Stiefel sum over a delay window, a lower bound, was fooled by the plateaus of plain CG and "
            f"IC(0)-PCG. Fixed-rtol runs start from zero. Column 'bound / eta' is the test's own value at the stop "
            f"(<= {frac:g}); 'algebraic / discretisation' is the measured ratio ||u_nested - u_l||_A / ||u - u_l||_A "
            f"(u_l by a direct solve; target {frac:g}). The target is in the energy norm: the algebraic error CG "
            f"leaves is smooth, so the L2 error may grow by more than the energy error (compare the L2 columns); "
            f"ask for a smaller fraction when L2 matters.")
        cols = ["solver", "level", "dofs", "iterations_fixed", "iterations_nested", "t_solve_fixed",
                "t_solve_nested", "L2_fixed", "L2_nested", "bound_over_estimate", "algebraic_over_discretisation"]
        report.table(cols, [[n.get(c) for c in cols] for n in nested])
        for s in dict.fromkeys(n["solver"] for n in nested):
            rows_n = [n for n in nested if n["solver"] == s and n["level"] > 0]
            itf = sum(n["iterations_fixed"] for n in rows_n)
            itn = sum(n["iterations_nested"] for n in rows_n)
            tf = sum(n["t_solve_fixed"] for n in rows_n)
            tn = sum(n["t_solve_nested"] for n in rows_n)
            report.paragraph(f"{s}: levels 1+ need {itn} iterations instead of {itf} "
                             f"({100 * (1 - itn / max(itf, 1)):.0f}% saved), solve time {tn:.3g} s instead of "
                             f"{tf:.3g} s.")


def summary(result) -> list[str]:
    """The lines ``femkit study`` prints: one per group of solvers with the same fit, like the
    report's table."""
    return [f"rate {who} / {rule} / {norm}: {slope:.3f} ({r2_text(r2)})"
            for who, rule, norm, slope, _, r2, *_ in grouped_rate_rows(result.fits)]


def _solution_figure(report, study, data, stage, rule: str) -> None:
    """A 3D study shows its solution on the second finest mesh, clipped open through the centre
    (a direct solve; pyvista renders it off screen: ``femkit[view]``). Without pyvista, or
    without off-screen OpenGL, the report says so in one sentence and is otherwise the same."""
    meshes = data.get("meshes") or []
    if not meshes or meshes[0].dim != 3:
        return
    from ...errors import ViewUnavailableError
    from ..problem import study_problem

    mesh = meshes[-2] if len(meshes) > 1 else meshes[-1]
    try:
        from ...case.poisson.view import solution_picture
        from ...view.core.render import screenshot

        u = study_problem(study).problem(mesh, rule).solve("direct").u
        picture = solution_picture(mesh, u, study.name)
        screenshot(picture, stage / "figures" / "solution_3d.png", size=(960, 720))
    except ViewUnavailableError as exc:
        report.paragraph(f"(No 3D picture of the solution: {exc}.)")
        return
    report.figure("figures/solution_3d.png",
                  f"The discrete solution u on {mesh.n_cells} tetrahedra ({rule} load rule), clipped "
                  "through the centre normal to (1, 1, 1); the whole boundary as a grey ghost")
