"""``kind: poisson_convergence``: mesh levels x solvers x quadrature rules, with fitted rates.

Per run it records h, dofs, nnz, the L2 / H1-seminorm / max nodal errors, iterations, the true
residual and the wall time of each stage (mesh, assembly, boundary, solve, errors). The run
time of the work-precision diagram is ``assembly + boundary + solve`` (what producing the
answer costs once the mesh exists; mesh generation is reported separately, error evaluation
is not part of the answer).

Options: ``reference: scikit-fem`` adds scikit-fem (default P1 basis, ``condense``) solved with
pyamg smoothed aggregation + SciPy CG on the same meshes; ``stop_at_discretisation_error``
adds nested-iteration runs (see :func:`_nested_runs`).
"""

from __future__ import annotations

import time

import numpy as np

from .fit import fit_rate
from .progress import progress
from .timing import StageTimer, time_call


def solver_label(s: dict) -> str:
    if s.get("label"):
        return s["label"]
    pc = s.get("preconditioner")
    return s["method"] if not pc or pc == "none" else f"{s['method']}+{pc}"


def _meshes(study, spec, timer_list):
    """The mesh levels: uniform refinements of one mesh, or one gmsh mesh per h."""
    from ..mesh import refine

    lv = study.data["levels"]
    meshes = []
    if "h" in lv:
        hs = list(lv["h"])
        if "max_level" in lv:
            hs = hs[: lv["max_level"] + 1]
        for h in hs:
            t0 = time.perf_counter()
            meshes.append(spec.base_mesh(h))
            timer_list.append(time.perf_counter() - t0)
    else:
        count = lv["count"] if "max_level" not in lv else min(lv["count"], lv["max_level"] + 1)
        t0 = time.perf_counter()
        m = spec.base_mesh(lv["h0"])
        timer_list.append(time.perf_counter() - t0)
        meshes.append(m)
        for _ in range(count - 1):
            t0 = time.perf_counter()
            m = refine(m, 1)
            timer_list.append(time.perf_counter() - t0)
            meshes.append(m)
    return meshes


def _assemble(spec, mesh, rule):
    from ..fem import assemble_load, assemble_stiffness

    kappa = spec.kappa_elements(mesh)
    K = assemble_stiffness(mesh, kappa)
    F = assemble_load(mesh, spec.source, rule=rule)
    if spec.neumann is not None:
        F = F + spec.neumann(mesh)
    return K, F


def _boundary(spec, mesh, K, F):
    from ..fem import apply_dirichlet

    nodes, vals = spec.dirichlet(mesh)
    return apply_dirichlet(K, F, nodes, vals)


def _errors(spec, mesh, u, order):
    from ..fem import error_norms

    return error_norms(mesh, u, spec.exact, spec.grad_exact, order=order)


def _solve(sys, s, x0=None, atol=None):
    from ..solvers import solve

    kw = {"method": s["method"], "rtol": s.get("rtol", 1e-10), "atol": s.get("atol", 0.0) if atol is None else atol}
    if s["method"] == "pcg":
        kw["preconditioner"] = s.get("preconditioner") or "amg"
    elif s.get("preconditioner") not in (None, "none"):
        kw["preconditioner"] = s["preconditioner"]
    if s.get("maxiter"):
        kw["maxiter"] = s["maxiter"]
    return solve(sys.A, sys.b, x0, **kw)


def interpolate_nested(coarse, fine, u_coarse: np.ndarray) -> np.ndarray:
    """P1 interpolation of ``u_coarse`` onto ``fine = refine(coarse)``.

    The refinement is nested: the first ``n`` fine nodes are the coarse nodes, then one
    midpoint per coarse edge (in :func:`femkit.mesh.edges` order), which takes the average of
    its edge's end values.
    """
    from ..mesh import edges

    n = coarse.n_points
    edge_nodes, _ = edges(coarse)
    if fine.n_points != n + len(edge_nodes) or not np.array_equal(fine.points[:n], coarse.points):
        raise ValueError("fine mesh is not the uniform refinement of the coarse mesh")
    return np.concatenate([u_coarse, u_coarse[edge_nodes].mean(axis=1)])


def _record(level, mesh, sys, rule, label, s, res, errs, times, *, source="femkit", mode="fixed_rtol", h=None):
    from ..mesh import quality

    h = quality(mesh)["h_max"] if h is None else h
    rec = {
        "source": source, "mode": mode, "level": level, "h": float(h), "nodes": mesh.n_points,
        "elements": mesh.n_triangles, "dofs": int(sys.A.shape[0]), "nnz": int(sys.A.nnz),
        "quadrature": rule, "solver": label, "method": s.get("method"),
        "preconditioner": s.get("preconditioner") or ("amg" if s.get("method") == "pcg" else "none"),
        "converged": bool(res.converged), "iterations": int(res.iterations),
        "true_residual": float(res.true_residual), "relative_residual": float(res.relative_residual),
        "L2": errs["L2"], "H1_semi": errs["H1_semi"], "max_nodal": errs["max_nodal"],
    }
    for k in ("mesh", "assembly", "boundary", "solve", "errors"):
        rec[f"t_{k}"] = float(times.get(k, np.nan))
    rec["t_total"] = rec["t_assembly"] + rec["t_boundary"] + rec["t_solve"]
    return rec


def _skfem_run(spec, mesh, rtol, repeats):
    """scikit-fem assembly + condense, pyamg SA + SciPy CG: (nodal u, iterations, relres, times, A)."""
    import pyamg
    import scipy.sparse.linalg as spla
    import skfem
    from skfem.helpers import dot, grad

    kappa = spec.kappa_elements(mesh)
    f = spec.source

    @skfem.BilinearForm
    def a(u, v, w):
        return w["kap"] * dot(grad(u), grad(v))

    @skfem.LinearForm
    def L(v, w):
        return f(w.x[0], w.x[1]) * v

    def assemble():
        m = skfem.MeshTri(mesh.points.T.copy(), mesh.triangles.T.copy())
        basis = skfem.Basis(m, skfem.ElementTriP1())
        kap = np.repeat(kappa[:, None], basis.X.shape[1], axis=1)
        return a.assemble(basis, kap=kap), L.assemble(basis)

    ta = time_call(assemble, repeats=repeats, warmup=0)
    K, F = ta.value
    nodes, vals = spec.dirichlet(mesh)
    x = np.zeros(mesh.n_points)
    x[nodes] = vals
    tb = time_call(lambda: skfem.condense(K, F, x=x, D=nodes), repeats=repeats, warmup=0)
    A, b, xI, I = tb.value

    def run():
        it = [0]
        ml = pyamg.smoothed_aggregation_solver(A)
        sol, info = spla.cg(A, b, rtol=rtol, atol=0.0, M=ml.aspreconditioner(),
                            callback=lambda xk: it.__setitem__(0, it[0] + 1), maxiter=10000)
        return sol, it[0]

    ts = time_call(run, repeats=repeats, warmup=0)
    sol, iters = ts.value
    u = x.copy()
    u[I] = sol
    relres = float(np.linalg.norm(b - A @ sol) / max(np.linalg.norm(b), 1e-300))
    return u, iters, relres, {"assembly": ta.min, "boundary": tb.min, "solve": ts.min}, A


class _Res:  # minimal SolveResult stand-in for the reference rows
    def __init__(self, iters, relres, bnorm):
        self.converged = True
        self.iterations = iters
        self.relative_residual = relres
        self.true_residual = relres * bnorm


def run_poisson_study(study, *, progress_enabled=None) -> dict:
    """Run the sweep; return ``{"records", "fits", "nested", "meshes", "notes"}``."""
    from .problem import case_spec, inline_spec

    d = study.data
    spec = inline_spec(d["problem"]) if "problem" in d else case_spec(study.resolve(d["base_case"]))
    repeats, warmup, order = d["repeats"], d["warmup"], d["error_order"]
    mesh_times: list[float] = []
    meshes = _meshes(study, spec, mesh_times)
    rules, solvers = d["quadrature"], d["solvers"]
    notes = []
    if warmup:
        # untimed pass on the coarsest mesh: imports, numba compilation, pyamg import
        for rule in rules:
            K, F = _assemble(spec, meshes[0], rule)
            sys0 = _boundary(spec, meshes[0], K, F)
            for s in solvers:
                _solve(sys0, s)
    records = []
    jobs = [(lvl, rule) for lvl in range(len(meshes)) for rule in rules]
    for lvl, rule in progress(jobs, total=len(jobs), desc=f"{study.name}", enabled=progress_enabled):
        mesh = meshes[lvl]
        ta = time_call(lambda: _assemble(spec, mesh, rule), repeats=repeats, warmup=0)
        K, F = ta.value
        tb = time_call(lambda: _boundary(spec, mesh, K, F), repeats=repeats, warmup=0)
        sys = tb.value
        for s in solvers:
            ts = time_call(lambda: _solve(sys, s), repeats=repeats, warmup=0)
            res = ts.value
            timer = StageTimer()
            with timer("errors"):
                errs = _errors(spec, mesh, sys.expand(res.x), order)
            times = {"mesh": mesh_times[lvl], "assembly": ta.min, "boundary": tb.min,
                     "solve": ts.min, "errors": timer.times["errors"]}
            records.append(_record(lvl, mesh, sys, rule, solver_label(s), s, res, errs, times))
    if d["reference"] == "scikit-fem":
        if spec.neumann is not None:
            notes.append("scikit-fem reference skipped: the base case has Neumann boundaries.")
        else:
            rtol = solvers[0].get("rtol", 1e-10)
            for lvl, mesh in enumerate(meshes):
                u, iters, relres, times, A = _skfem_run(spec, mesh, rtol, repeats)
                errs = _errors(spec, mesh, u, order)
                times["mesh"] = mesh_times[lvl]
                sys_like = type("S", (), {"A": A})()
                s = {"method": "cg", "preconditioner": "pyamg_sa"}
                records.append(_record(lvl, mesh, sys_like, "skfem-default", "scikit-fem+pyamg", s,
                                       _Res(iters, relres, 1.0), errs, times, source="scikit-fem"))
            notes.append(f"scikit-fem reference: skfem {__import__('skfem').__version__} P1 (default 3-point "
                         f"quadrature), condense, pyamg smoothed aggregation + SciPy CG to rtol {rtol:g}.")
    nested = []
    if d.get("stop_at_discretisation_error") is not None and "h" not in d["levels"]:
        nested = _nested_runs(study, spec, meshes, mesh_times, records)
    elif d.get("stop_at_discretisation_error") is not None:
        notes.append("stop_at_discretisation_error needs nested levels (levels: {h0, count}); skipped.")
    fits = fit_all(records)
    return {"records": records, "fits": fits, "nested": nested, "notes": notes, "meshes": meshes}


def _energy_norm(A, d) -> float:
    return float(np.sqrt(max(float(d @ (A @ d)), 0.0)))


HS_DELAY = 4


def _stop_iteration(increments: np.ndarray, fraction: float, eta: float | None,
                    delay: int = HS_DELAY) -> tuple[int | None, float]:
    """First iteration ``m`` at which the delayed Hestenes-Stiefel test passes, and the eta used.

    ``increments[j] = ||x_{j+1} - x_j||_A^2`` (``alpha_j ||r_j||^2`` for (P)CG). At iteration ``m``
    the algebraic error of iterate ``k = min(m - delay, m // 4)`` is estimated by
    ``sum_{j=k}^{m-1} increments[j]`` (a lower bound that tightens with the window; a fixed short
    window misses the plateaus of unpreconditioned CG). The iterate returned is ``x_m``, better still. ``eta`` is the estimated discretisation error
    (energy norm) of this level; ``None`` (the first nested level, whose start is the exactly
    solved coarsest level) estimates it from the start's algebraic error
    ``||u_1 - u_0||_A^2 ~ sum_j increments[j]`` over ``sqrt(3)`` (Galerkin orthogonality on nested
    spaces with H1 rate 1: ``||u - u_0||^2 = ||u - u_1||^2 + ||u_1 - u_0||^2``, ``||u - u_1|| = ||u - u_0|| / 2``).
    The test is ``estimate <= (fraction * eta)^2``.
    """
    c = np.concatenate([[0.0], np.cumsum(increments)])
    if eta is None:
        eta = float(np.sqrt(c[-1] / 3.0))
    for m in range(delay, len(increments) + 1):
        k = min(m - delay, m // 4)  # the window grows with m: short windows miss CG plateaus
        if c[m] - c[k] <= (fraction * eta) ** 2:
            return m, eta
    return None, eta


def _nested_runs(study, spec, meshes, mesh_times, records):
    """Nested iteration stopped at a fraction of the estimated discretisation error ((P)CG only).

    Level 0 is solved from zero with the solver's fixed ``rtol``. On level ``l >= 1`` the start is
    the coarse nested solution interpolated to the refined mesh; an untimed analysis pass records
    the energy-norm increments of the iterates and :func:`_stop_iteration` picks the iteration at
    which the algebraic error is ``fraction`` x the estimated discretisation error (estimated on
    level 1, then halved per level); the timed run
    then stops there (``maxiter``). The report checks the estimate afterwards: the attained algebraic
    error ``||u_nested - u_fixed||_A`` against the H1 discretisation error of the fixed-rtol run.
    """
    d = study.data
    frac = d["stop_at_discretisation_error"]["fraction"]
    rule = d["quadrature"][0]
    out = []
    for s in d["solvers"]:
        if s["method"] not in ("cg", "pcg"):
            continue
        label = solver_label(s)
        prev = None
        eta = None
        for lvl, mesh in enumerate(meshes):
            K, F = _assemble(spec, mesh, rule)
            sys = _boundary(spec, mesh, K, F)
            fixed = next(r for r in records if r["source"] == "femkit" and r["level"] == lvl
                         and r["solver"] == label and r["quadrature"] == rule)
            ref = _solve(sys, s)
            stop = None
            if prev is None:
                x0 = None
                tc = time_call(lambda: _solve(sys, s), repeats=d["repeats"], warmup=0)
            else:
                x0 = interpolate_nested(meshes[lvl - 1], mesh, prev)[sys.free]
                incs, last = [], [x0.copy()]

                def cb(xk):
                    dx = xk - last[0]
                    incs.append(float(dx @ (sys.A @ dx)))
                    last[0] = np.array(xk, copy=True)

                from ..solvers import solve as _raw_solve  # analysis pass, untimed

                kw = {k: v for k, v in s.items() if k in ("rtol", "atol", "maxiter")}
                if s["method"] == "pcg":
                    kw["preconditioner"] = s.get("preconditioner") or "amg"
                _raw_solve(sys.A, sys.b, x0.copy(), method=s["method"], callback=cb, **kw)
                stop, eta = _stop_iteration(np.array(incs), frac, eta)
                s_run = s if stop is None else {**s, "maxiter": max(stop, 1)}
                tc = time_call(lambda: _solve(sys, s_run, x0=x0.copy()), repeats=d["repeats"], warmup=0)
            res, t_solve = tc.value, tc.min  # min over repeats, like the fixed-rtol runs
            u = sys.expand(res.x)
            prev = u
            eta_used = eta
            if eta is not None:
                eta = eta / 2.0  # H1 rate 1: the next level's discretisation error halves
            errs = _errors(spec, mesh, u, d["error_order"])
            alg = _energy_norm(sys.A, res.x - ref.x)
            disc = fixed["H1_semi"]
            out.append({
                "solver": label, "level": lvl, "dofs": fixed["dofs"], "h": fixed["h"],
                "iterations_fixed": fixed["iterations"], "iterations_nested": int(res.iterations),
                "t_solve_fixed": fixed["t_solve"], "t_solve_nested": t_solve,
                "L2_fixed": fixed["L2"], "L2_nested": errs["L2"],
                "H1_fixed": disc, "H1_nested": errs["H1_semi"],
                "algebraic_error_energy": alg, "estimated_discretisation_error": eta_used,
                "algebraic_over_discretisation": (alg / disc) if disc else None,
                "stopped_by_estimate": stop is not None, "fraction": frac,
            })
    return out


def fit_all(records) -> list[dict]:
    """Fitted rates vs h of every (source, solver, quadrature) line and error norm."""
    fits = []
    keys = list(dict.fromkeys((r["source"], r["solver"], r["quadrature"]) for r in records))
    for key in keys:
        rows = [r for r in records if (r["source"], r["solver"], r["quadrature"]) == key]
        for norm in ("L2", "H1_semi", "max_nodal"):
            pts = [(r["h"], r[norm]) for r in rows if r[norm] is not None and r[norm] > 0]
            if len(pts) < 2:
                continue
            h, e = np.array(pts).T
            f = fit_rate(h, e)
            fits.append({"source": key[0], "solver": key[1], "quadrature": key[2], "norm": norm,
                         **f.as_dict(), "fit": f})
    return fits
