"""``kind: element_work_precision``: each element on uniform refinements of one mesh, timed.

Per run it records the element, the level, h, the free unknowns, the nonzeros, the L2 and H1
errors and the run time ``assembly + boundary + solve`` (the minimum over ``repeats``: what
producing the answer costs once the mesh exists, as in ``poisson_convergence``), then fits the
error against the unknowns per element and finds the crossover (:func:`crossover`): the error
below which the higher-order element reaches the same accuracy in less time (and with fewer
unknowns).
"""

from __future__ import annotations

import numpy as np

from ...interrupt import checkpoint
from ...progress import Progress
from ..fit import fit_rate
from ..timing import time_call

__all__ = ["run", "crossover"]

NORMS = ("L2", "H1_semi")


def _answer(problem, solver):
    """Assemble, reduce, solve: the timed work of one run; ``(u, result, system)``."""
    K, F = problem.assemble_matrices()
    system = problem.reduce(K, F, solver.method)
    res = solver.solve(system.A, system.b)
    return system.expand(res.x), res, system


def run(study, *, progress_enabled=None) -> dict:
    """Run the sweep; return ``{"records", "fits", "tables": {"crossover"}, "notes"}``."""
    from ...case.cost import check_mesh_fits
    from ...case.poisson.run import poisson_problem
    from ...case.specs import solver_spec
    from ...mesh import refine
    from ..problem import study_problem

    d = study.spec
    case = study_problem(study).case
    solver = solver_spec(d.solver, "solver")
    exact, grad = case.functions["exact.u"], _gradient(case)
    base = study_problem(study).base_mesh(d.h0)
    jobs = [(e, k) for e, count in zip(d.elements, d.counts) for k in range(count)]
    bar = Progress(len(jobs), study.name, unit="run", quiet=progress_enabled is False)
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
        records.append({"element": element, "level": level, "cells": mesh.n_cells,
                        "h": float(d.h0) / 2 ** level, "dofs": int(system.A.shape[0]),
                        "nnz": int(system.A.nnz), "iterations": int(res.iterations),
                        "converged": bool(res.converged), "t": t.min, "t_median": t.median,
                        "L2": errs["L2"], "H1_semi": errs["H1_semi"]})
        bar.update()
    bar.close()
    fits = []
    for element in d.elements:
        rows = [r for r in records if r["element"] == element]
        for norm in NORMS:
            f = fit_rate([r["dofs"] for r in rows], [r[norm] for r in rows])
            fits.append({"element": element, "norm": norm, "rate_vs_dofs": f.slope, "fit": f})
    cross = [crossover(records, a, b, norm) for i, a in enumerate(d.elements)
             for b in d.elements[i + 1:] for norm in NORMS]
    failed = [r for r in records if not r["converged"]]
    notes = [f"{len(failed)} run(s) did not converge: their errors include the algebraic error"] if failed else []
    return {"records": records, "fits": fits, "tables": {"crossover": cross}, "notes": notes}


def _gradient(case):
    comps = [case.functions[k] for k in sorted(case.functions) if k.startswith("exact.grad[")]
    return lambda *x: tuple(g(*x) for g in comps)


def crossover(records, low: str, high: str, norm: str, cost: str = "t") -> dict:
    """Where ``high`` (e.g. P2) becomes cheaper than ``low`` (P1) in ``cost`` (``"t"`` run
    time, or ``"dofs"``) at equal ``norm`` error.

    Each element's cost is interpolated as a function of the error, linearly in log-log between
    its runs; on the errors both cover, the crossover is the largest error below which ``high``
    is cheaper at every error (``None`` when it never is in that range, or is everywhere, then
    ``"everywhere": True``).

    >>> recs = [{"element": "P1", "t": t, "L2": e} for t, e in ((1, 1e-2), (4, 2.5e-3), (16, 6e-4))]
    >>> recs += [{"element": "P2", "t": t, "L2": e} for t, e in ((2, 1e-2), (5, 1.2e-3), (12, 1.5e-4))]
    >>> c = crossover(recs, "P1", "P2", "L2")   # P1: t = 3.33 at 3e-3 (log-log), P2: 3.37
    >>> round(c["error"], 3), c["everywhere"]
    (0.003, False)
    """
    def curve(el):
        rows = sorted((r for r in records if r["element"] == el and r[norm] and r[cost] > 0),
                      key=lambda r: r[norm])
        return np.log([r[norm] for r in rows]), np.log([r[cost] for r in rows])

    (ea, ta), (eb, tb) = curve(low), curve(high)
    out = {"low": low, "high": high, "norm": norm, "cost": cost, "error": None, "everywhere": False,
           "range": None}
    if len(ea) < 2 or len(eb) < 2:
        return out
    lo, hi = max(ea.min(), eb.min()), min(ea.max(), eb.max())
    if not lo < hi:
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
