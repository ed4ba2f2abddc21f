"""``kind: element_work_precision``: each element on uniform refinements of one mesh, timed.

Per run it records the series (the element; ``"<element> adaptive"`` for an adaptive series),
the level, h, the free unknowns, the nonzeros, the errors and the run time, then fits the error
against the unknowns per series and finds the crossovers (:func:`crossover`): the error below
which one series reaches the same accuracy in less time.

Three sources of runs:

- a Poisson case on uniform refinements: L2 and H1-seminorm errors against ``exact``; the run
  time is ``assembly + boundary + solve`` on the level (the minimum over ``repeats``: what
  producing the answer costs once the mesh exists, as in ``poisson_convergence``);
- ``adaptive:`` (Poisson): each listed element also through the adaptive loop
  (:func:`femkit.fem.adaptive.adaptive_solve`, from the same ``h0`` mesh): the energy error
  (the H1 seminorm for ``coefficient: 1``) per level, and as run time the wall time since the
  loop started (every coarser level's solve, estimate, marking and refinement: what reaching
  that level costs);
- a solid base case (:mod:`.solid`): the relative error of one displacement component at one
  node against ``reference.value``.
"""

from __future__ import annotations

import numpy as np

from ...interrupt import checkpoint
from ...progress import Progress
from ..fit import fit_rate
from ..timing import time_call

__all__ = ["run", "crossover", "summarise", "NORMS"]

NORMS = ("L2", "H1_semi")


def _answer(problem, solver):
    """Assemble, reduce, solve: the timed work of one run; ``(u, result, system)``."""
    K, F = problem.assemble_matrices()
    system = problem.reduce(K, F, solver.method)
    res = solver.solve(system.A, system.b)
    return system.expand(res.x), res, system


def run(study, *, progress_enabled=None) -> dict:
    """Run the sweep; return ``{"records", "fits", "tables": {"crossover"}, "notes"}``."""
    d = study.spec
    quiet = progress_enabled is False
    pairs = [(a, b) for i, a in enumerate(d.elements) for b in d.elements[i + 1:]]
    if d.reference is not None:
        from .solid import solid_records

        return summarise(solid_records(study, quiet=quiet), d.elements, ("corner",), pairs)
    records = _poisson_records(study, quiet)
    if d.adaptive is not None:
        records += _adaptive_records(study, quiet)
    if d.adaptive is not None:
        ad = list(d.adaptive["elements"])
        pairs += [(e, f"{e} adaptive") for e in ad if e in d.elements]
        pairs += [(f"{a} adaptive", f"{b} adaptive") for i, a in enumerate(ad) for b in ad[i + 1:]]
    return summarise(records, d.series(), NORMS, pairs)


def _poisson_records(study, quiet: bool) -> list[dict]:
    """The uniform runs of a Poisson case: one record per (element, level)."""
    from ...case.cost import check_mesh_fits
    from ...case.poisson.problem import exact_gradient
    from ...case.poisson.run import poisson_problem
    from ...case.specs import solver_spec
    from ...mesh import refine
    from ..problem import study_problem

    d = study.spec
    case = study_problem(study).case
    solver = solver_spec(d.solver, "solver")
    exact, grad = case.functions["exact.u"], exact_gradient(case)
    base = study_problem(study).base_mesh(d.h0)
    jobs = [(e, k) for e, count in zip(d.elements, d.counts) for k in range(count)]
    bar = Progress(len(jobs), study.name, unit="run", quiet=quiet)
    meshes = [base]
    records = []
    if d.warmup:  # untimed: imports, compiled kernels, the preconditioner's first set-up
        for e in d.elements:
            _answer(poisson_problem(case, base, element=e), solver)
    for element, level in jobs:
        checkpoint(f"before {element} level {level}")
        while len(meshes) <= level:
            check_mesh_fits(triangles=meshes[-1].n_cells, refine=1, dim=meshes[-1].dim)  # before numpy allocates
            meshes.append(refine(meshes[-1], 1))
        mesh = meshes[level]
        problem = poisson_problem(case, mesh, element=element)
        t = time_call(lambda: _answer(problem, solver), repeats=d.repeats, warmup=0)
        u, res, system = t.value
        errs = problem.errors(u, exact, grad, order=d.error_order)
        records.append({"element": element, "refinement": "uniform", "level": level,
                        "cells": mesh.n_cells, "h": float(d.h0) / 2 ** level,
                        "dofs": int(system.A.shape[0]), "nnz": int(system.A.nnz),
                        "iterations": int(res.iterations), "converged": bool(res.converged),
                        "t": t.min, "t_median": t.median, "L2": errs["L2"], "H1_semi": errs["H1_semi"]})
        bar.update()
    bar.close()
    return records


def _adaptive_records(study, quiet: bool) -> list[dict]:
    """Each ``adaptive.elements`` element through the adaptive loop from the ``h0`` mesh: one
    record per level, ``t`` the loop's wall time up to that level's estimate."""
    from ...case.poisson.problem import exact_gradient
    from ...case.poisson.run import poisson_problem
    from ...case.specs import solver_spec
    from ...elements import get_element
    from ...fem.adaptive import adaptive_solve, problem_solver
    from ..problem import study_problem

    d, a = study.spec, study.spec.adaptive
    case = study_problem(study).case
    solver = solver_spec(d.solver, "solver")
    mesh0 = study_problem(study).base_mesh(d.h0)
    records = []
    bar = Progress(len(a["elements"]), f"{study.name} (adaptive)", unit="loop", quiet=quiet)
    for element in a["elements"]:
        checkpoint(f"before {element} adaptive")
        solve_on = problem_solver(lambda m, e=element: poisson_problem(case, m, element=e),
                                  solver.solve, solver.method)
        solve_on(mesh0, None)                   # warm-up: imports, compiled kernels, AMG
        nodes_per_dof = get_element(element, mesh0.dim).degree ** mesh0.dim   # P2: ~4 (2D), ~8 (3D)
        loop = adaptive_solve(solve_on, mesh0, theta=a["theta"], estimator=a["estimator"],
                              max_dofs=max(a["max_dofs"] // nodes_per_dof, mesh0.n_points + 1),
                              max_levels=None, grad_exact=exact_gradient(case))   # max_dofs bounds it
        for lv in loop.levels:
            records.append({"element": f"{element} adaptive", "refinement": "adaptive",
                            "level": lv.level, "cells": lv.n_elements, "h": None, "dofs": lv.dofs,
                            "nnz": None, "iterations": lv.iterations, "converged": lv.converged,
                            "t": lv.elapsed, "t_median": None, "L2": None, "H1_semi": lv.error})
        bar.update()
    bar.close()
    return records


def summarise(records: list[dict], series, norms, pairs) -> dict:
    """Fits (error against unknowns per series and norm) and the crossovers of ``pairs``
    (``(low, high)`` series) for every norm both series measured; the study's result dict."""
    fits = []
    for name in series:
        for norm in norms:
            rows = [r for r in records if r["element"] == name and r.get(norm) is not None]
            if len(rows) >= 2:
                f = fit_rate([r["dofs"] for r in rows], [r[norm] for r in rows])
                fits.append({"element": name, "norm": norm, "rate_vs_dofs": f.slope, "fit": f})
    measured = {(r["element"], n) for r in records for n in norms if r.get(n) is not None}
    cross = [crossover(records, a, b, n) for n in norms for a, b in pairs
             if (a, n) in measured and (b, n) in measured]
    failed = [r for r in records if not r["converged"]]
    notes = [f"{len(failed)} run(s) did not converge: their errors include the algebraic error"] if failed else []
    return {"records": records, "fits": fits, "tables": {"crossover": cross}, "notes": notes}


def crossover(records, low: str, high: str, norm: str, cost: str = "t") -> dict:
    """Where ``high`` (e.g. P2) becomes cheaper than ``low`` (P1) in ``cost`` (``"t"`` run
    time, or ``"dofs"``) at equal ``norm`` error.

    Each series' cost is interpolated as a function of the error, linearly in log-log between
    its runs; on the errors both cover, the crossover is the largest error below which ``high``
    is cheaper at every error (``None`` when it never is in that range, or is everywhere, then
    ``"everywhere": True``). When the two error ranges do not overlap (``"range": None``),
    ``"apart"`` says how: ``high_errors``, ``low_errors`` (each ``[min, max]``) and the costs
    ``high_min_cost``, ``low_max_cost``, so "every ``high`` run is more accurate than every
    ``low`` run, and its cheapest costs less than ``low``'s dearest" can be said.

    >>> recs = [{"element": "P1", "t": t, "L2": e} for t, e in ((1, 1e-2), (4, 2.5e-3), (16, 6e-4))]
    >>> recs += [{"element": "P2", "t": t, "L2": e} for t, e in ((2, 1e-2), (5, 1.2e-3), (12, 1.5e-4))]
    >>> c = crossover(recs, "P1", "P2", "L2")   # P1: t = 3.33 at 3e-3 (log-log), P2: 3.37
    >>> round(c["error"], 3), c["everywhere"]
    (0.003, False)
    """
    def curve(el):
        rows = sorted((r for r in records if r["element"] == el and r.get(norm) and r[cost] > 0),
                      key=lambda r: r[norm])
        return np.log([r[norm] for r in rows]), np.log([r[cost] for r in rows])

    (ea, ta), (eb, tb) = curve(low), curve(high)
    out = {"low": low, "high": high, "norm": norm, "cost": cost, "error": None, "everywhere": False,
           "range": None, "apart": None}
    if len(ea) < 2 or len(eb) < 2:
        return out
    lo, hi = max(ea.min(), eb.min()), min(ea.max(), eb.max())
    if not lo < hi:
        out["apart"] = {"high_errors": [float(np.exp(eb.min())), float(np.exp(eb.max()))],
                        "low_errors": [float(np.exp(ea.min())), float(np.exp(ea.max()))],
                        "high_min_cost": float(np.exp(tb.min())), "low_max_cost": float(np.exp(ta.max()))}
        return out
    grid = np.linspace(lo, hi, 400)
    cheaper = np.interp(grid, eb, tb) < np.interp(grid, ea, ta)     # high cheaper at this error
    out["range"] = [float(np.exp(lo)), float(np.exp(hi))]
    if cheaper.all():
        out["everywhere"] = True
        out["error"] = float(np.exp(hi))
    elif cheaper[0]:
        # the largest error below which high is cheaper everywhere (the first change from below)
        first_bad = int(np.argmin(cheaper))
        out["error"] = float(np.exp(grid[first_bad]))
    return out
