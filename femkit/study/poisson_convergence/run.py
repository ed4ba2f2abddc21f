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

import numpy as np

from ...interrupt import checkpoint
from ...progress import Progress
from ..fit import fit_rate
from ..timing import StageTimer, time_call


def _meshes(study, spec, timer_list):
    """The mesh levels: uniform refinements of one mesh, or one gmsh mesh per h; the time of
    each level is appended to ``timer_list``. Returns the meshes and ``hierarchy(level)``: the
    :class:`~femkit.mesh.MeshHierarchy` of levels ``0 .. level`` (refinements only; ``None``
    for gmsh meshes per h, which are not nested), for geometric multigrid."""
    from ...mesh import MeshHierarchy, edges, refine
    from ...mesh.hierarchy import prolongation

    lv = study.spec.levels
    meshes = []
    timer = StageTimer()

    def timed(level, make):
        with timer(level):
            meshes.append(make())
        timer_list.append(timer.times[level])

    sizes = lv.sizes()
    if not lv.nested:
        for i, (h, _) in enumerate(sizes):
            timed(i, lambda h=h: spec.base_mesh(h))
        return meshes, lambda level: None
    count = len(sizes)
    timed(0, lambda: spec.base_mesh(lv.h0))
    from ...case.cost import check_mesh_fits

    for i in range(1, count):
        check_mesh_fits(triangles=meshes[-1].n_cells, refine=1, dim=meshes[-1].dim)  # before numpy allocates
        timed(i, lambda: refine(meshes[-1], 1))

    prols: list = []  # built once, on the first request that reaches them

    def hierarchy(level: int):
        # refine() numbers the coarse nodes first, then one midpoint per edges() edge
        for m in meshes[len(prols):level]:
            prols.append(prolongation(m.n_points, edges(m)[0]))
        injs = tuple(np.arange(m.n_points, dtype=np.int64) for m in meshes[:level])
        return MeshHierarchy(tuple(meshes[: level + 1]), tuple(prols[:level]), injs, "none")

    return meshes, hierarchy


def _assemble(spec, mesh, rule):
    """The level's PoissonProblem (the one pipeline) and its K, F."""
    problem = spec.problem(mesh, rule)
    K, F = problem.assemble_matrices()
    return problem, K, F


def _solve(sys, s, x0=None, atol=None, mg=None):
    """Solve with a :class:`~femkit.solvers.SolverSpec` (``atol`` overrides the spec's; ``mg``:
    the geometric multigrid overrides of the level, :func:`_multigrid`)."""
    return s.solve(sys.A, sys.b, x0, **({} if atol is None else {"atol": atol}), **(mg or {}))


def _multigrid(s, hierarchy, sys, lower=None) -> dict:
    """Geometric multigrid arguments of solver ``s`` on a level (``{}`` for other solvers):
    its hierarchy, free nodes and, for ``fmg``, the lower levels' systems ``lower``."""
    from ...case.poisson.run import multigrid_overrides

    return multigrid_overrides(s, hierarchy, sys.free, lower)


def interpolate_nested(coarse, fine, u_coarse: np.ndarray) -> np.ndarray:
    """P1 interpolation of ``u_coarse`` onto ``fine = refine(coarse)``.

    The refinement is nested: the first ``n`` fine nodes are the coarse nodes, then one
    midpoint per coarse edge (in :func:`femkit.mesh.edges` order), which takes the average of
    its edge's end values.
    """
    from ...mesh import edges

    n = coarse.n_points
    edge_nodes, _ = edges(coarse)
    if fine.n_points != n + len(edge_nodes) or not np.array_equal(fine.points[:n], coarse.points):
        raise ValueError("fine mesh is not the uniform refinement of the coarse mesh")
    return np.concatenate([u_coarse, u_coarse[edge_nodes].mean(axis=1)])


def _record(level, mesh, sys, rule, label, s, res, errs, times, *, source="femkit", mode="fixed_rtol", h=None):
    from ...mesh import quality

    h = quality(mesh)["h_max"] if h is None else h
    rec = {
        "source": source, "mode": mode, "level": level, "h": float(h), "nodes": mesh.n_points,
        "elements": mesh.n_cells, "dofs": int(sys.A.shape[0]), "nnz": int(sys.A.nnz),
        "quadrature": rule, "solver": label, "method": s["method"], "preconditioner": s["preconditioner"],
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

    from ...case.poisson import reference

    problem = spec.problem(mesh)
    f = spec.case.functions["source"]
    ta = time_call(lambda: reference.assemble(mesh, problem.kappa, f), repeats=repeats, warmup=0)
    K, F = ta.value
    nodes, vals = problem.dirichlet_data()
    tb = time_call(lambda: reference.condense(K, F, nodes, vals), repeats=repeats, warmup=0)
    A, b, x, I = tb.value

    def run():
        it = [0]
        ml = pyamg.smoothed_aggregation_solver(A)
        sol, info = spla.cg(A, b, rtol=rtol, atol=0.0, M=ml.aspreconditioner(),
                            callback=lambda xk: it.__setitem__(0, it[0] + 1), maxiter=10000)
        return sol, it[0], info

    ts = time_call(run, repeats=repeats, warmup=0)
    sol, iters, info = ts.value
    u = x.copy()
    u[I] = sol
    relres = float(np.linalg.norm(b - A @ sol) / max(np.linalg.norm(b), 1e-300))
    # converged as femkit means it: SciPy said so *and* the true residual meets the rule
    converged = info == 0 and bool(relres <= rtol * (1 + 1e-6))
    return u, iters, relres, converged, {"assembly": ta.min, "boundary": tb.min, "solve": ts.min}, A


class _Res:  # minimal SolveResult stand-in for the reference rows
    def __init__(self, iters, relres, bnorm, converged):
        self.converged = converged
        self.iterations = iters
        self.relative_residual = relres
        self.true_residual = relres * bnorm


def run(study, *, progress_enabled=None) -> dict:
    """Run the sweep; return ``{"records", "fits", "nested", "meshes", "notes"}``."""
    from ..problem import study_problem

    d = study.spec
    spec = study_problem(study)
    repeats, warmup, order = d.repeats, d.warmup, d.error_order
    mesh_times: list[float] = []
    meshes, hierarchy = _meshes(study, spec, mesh_times)
    rules, solvers = d.quadrature, study.solvers
    multigrid = any(s.needs_hierarchy for s in solvers)
    notes = []
    if warmup:
        # untimed pass on the coarsest mesh: imports, numba compilation, pyamg import
        for rule in rules:
            prob0, K, F = _assemble(spec, meshes[0], rule)
            sys0 = prob0.reduce(K, F, "pcg")
            for s in solvers:
                _solve(sys0, s, mg=_multigrid(s, hierarchy(0), sys0, []))
    records = []
    systems = {}  # (level, rule) -> system: fmg's lower levels (its coarse right-hand sides)
    jobs = [(lvl, rule) for lvl in range(len(meshes)) for rule in rules]
    # one unit per record (a solver run, a scikit-fem reference run), the remaining time scaled
    # by the levels' triangles
    reference = d.reference == "scikit-fem" and not spec.has_neumann
    bar = Progress(len(jobs) * len(solvers) + (len(meshes) if reference else 0), study.name,
                   unit="run", quiet=progress_enabled is False,
                   cost=sum(m.n_cells for m in meshes) * (len(rules) * len(solvers) + reference))
    for lvl, rule in jobs:
        checkpoint(f"before level {lvl} ({rule})")
        mesh = meshes[lvl]
        ta = time_call(lambda: _assemble(spec, mesh, rule), repeats=repeats, warmup=0)
        prob, K, F = ta.value
        tb = time_call(lambda: prob.reduce(K, F, "pcg"), repeats=repeats, warmup=0)
        sys = tb.value
        H = hierarchy(lvl) if multigrid else None
        if multigrid:
            systems[lvl, rule] = sys
        lower = None if spec.pure_neumann or not multigrid else \
            [systems[i, rule] for i in range(lvl)]
        for s in solvers:
            mg = _multigrid(s, H, sys, lower)
            ts = time_call(lambda: _solve(sys, s, mg=mg), repeats=repeats, warmup=0)
            res = ts.value
            timer = StageTimer()
            with timer("errors"):
                errs = spec.errors(prob, sys.expand(res.x), order)
            times = {"mesh": mesh_times[lvl], "assembly": ta.min, "boundary": tb.min,
                     "solve": ts.min, "errors": timer.times["errors"]}
            records.append(_record(lvl, mesh, sys, rule, s.label, s.to_dict(), res, errs, times))
        bar.update(len(solvers), cost=len(solvers) * mesh.n_cells)
    if d.reference == "scikit-fem":
        if spec.has_neumann:
            notes.append("scikit-fem reference skipped: the base case has Neumann boundaries.")
        else:
            rtol = solvers[0].rtol
            if warmup:  # untimed: skfem's and pyamg's first calls are ~2x slower than the next ones
                _skfem_run(spec, meshes[0], rtol, 1)
            for lvl, mesh in enumerate(meshes):
                u, iters, relres, conv, times, A = _skfem_run(spec, mesh, rtol, repeats)
                errs = spec.errors(spec.problem(mesh), u, order)
                times["mesh"] = mesh_times[lvl]
                sys_like = type("S", (), {"A": A})()
                s = {"method": "cg", "preconditioner": "pyamg_sa"}
                records.append(_record(lvl, mesh, sys_like, "skfem-default", "scikit-fem+pyamg", s,
                                       _Res(iters, relres, 1.0, conv), errs, times, source="scikit-fem"))
                bar.update(1, cost=mesh.n_cells)
            element = "ElementTetP1, default 4-point" if meshes[0].dim == 3 else "P1, default 3-point"
            notes.append(f"scikit-fem reference: skfem {__import__('skfem').__version__} {element} "
                         f"quadrature, condense, pyamg smoothed aggregation + SciPy CG to rtol {rtol:g}.")
    bar.close()
    nested = []
    if d.stop_fraction is not None and d.levels.nested:
        nested = _nested_runs(study, spec, meshes, mesh_times, records, hierarchy)
    elif d.stop_fraction is not None:
        notes.append("stop_at_discretisation_error needs nested levels (levels: {h0, count}); skipped.")
    failed = [r for r in records if not r["converged"]]
    if failed:
        notes.append(unconverged_note(failed))
    fits = fit_all(records)
    return {"records": records, "fits": fits, "nested": nested, "notes": notes, "meshes": meshes}


def _energy_norm(A, d) -> float:
    return float(np.sqrt(max(float(d @ (A @ d)), 0.0)))


def cg_history(A, b, x0, s, mg=None) -> dict:
    """Untimed analysis pass of (P)CG: the coefficients a stopping test on the error needs.

    ``s`` is a :class:`~femkit.solvers.SolverSpec`. Runs femkit's solver with a callback (which receives only the iterate ``x_k``) and recovers
    per iteration, from one matrix-vector product and one preconditioner application,
    ``rz[k] = r_k^T z_k`` (``z = M^-1 r``; ``z = r`` for CG) and
    ``inc[k] = ||x_{k+1} - x_k||_A^2 = alpha_k r_k^T z_k`` (the Hestenes-Stiefel terms;
    ``A (x_{k+1} - x_k) = r_k - r_{k+1}``), hence ``alpha[k] = inc[k] / rz[k]``. ``mg``: the
    level's geometric multigrid overrides (:func:`_multigrid`) for ``preconditioner: gmg``.
    """
    from ...solvers import get_preconditioner, solve

    M = None
    kw = dict(rtol=s.rtol, atol=s.atol, maxiter=s.maxiter)
    if s.method == "pcg":
        pc_options = {**s.preconditioner_options, **(mg or {}).get("preconditioner_options", {})}
        M = get_preconditioner(s.preconditioner)(A, **pc_options)
        kw["preconditioner"] = M
    x_prev = [np.array(x0, dtype=float, copy=True)]
    r_prev = [b - A @ x_prev[0]]
    z0 = r_prev[0] if M is None else M(r_prev[0])
    rz, inc = [float(r_prev[0] @ z0)], []

    def cb(xk):
        r = b - A @ xk
        z = r if M is None else M(r)
        dx = xk - x_prev[0]
        inc.append(float(dx @ (r_prev[0] - r)))
        rz.append(float(r @ z))
        x_prev[0] = np.array(xk, copy=True)
        r_prev[0] = r

    solve(A, b, np.array(x0, dtype=float, copy=True), method=s.method, callback=cb, **kw)
    rz_a, inc_a = np.array(rz), np.array(inc)
    return {"rz": rz_a, "inc": inc_a, "alpha": inc_a / np.maximum(rz_a[:-1], 1e-300)}


def smallest_ritz_value(alpha: np.ndarray, rz: np.ndarray) -> float:
    """Smallest eigenvalue of the Lanczos (Jacobi) matrix built from the (P)CG coefficients.

    ``T`` has diagonal ``1/alpha_k + beta_k/alpha_{k-1}`` and off-diagonal ``sqrt(beta_{k+1})/alpha_k``
    with ``beta_k = rz_k / rz_{k-1}``; after a converged run its smallest eigenvalue approximates
    ``lambda_min(M^-1 A)`` from above.

    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(30, 30)).tocsr()
    >>> from femkit.solvers import SolverSpec
    >>> h = cg_history(A, np.ones(30), np.zeros(30), SolverSpec.from_mapping({"method": "cg", "rtol": 1e-12}))
    >>> lam = 2 - 2 * np.cos(np.pi / 31)     # exact smallest eigenvalue
    >>> bool(abs(smallest_ritz_value(h["alpha"], h["rz"]) / lam - 1) < 1e-6)
    True
    """
    n = len(alpha)
    if n == 0:
        return float("nan")
    beta = rz[1:n] / rz[: n - 1]
    diag = 1.0 / alpha
    diag[1:] += beta / alpha[:-1]
    off = np.sqrt(beta) / alpha[:-1]
    from scipy.linalg import eigvalsh_tridiagonal

    return float(eigvalsh_tridiagonal(diag, off, select="i", select_range=(0, 0))[0])


def gauss_radau_bounds(inc: np.ndarray, rz: np.ndarray, mu: float) -> np.ndarray:
    """Upper bounds ``U_k >= ||x - x_k||_A^2`` of every (P)CG iterate (Gauss-Radau quadrature).

    With ``0 < mu <= lambda_min(M^-1 A)`` (Meurant and Tichy's CGQ recurrence, preconditioned form)::

        U_0 = rz_0 / mu,   U_{k+1} = rz_{k+1} (U_k - inc_k) / (mu (U_k - inc_k) + rz_{k+1})

    where ``inc_k = alpha_k r_k^T z_k``. Unlike the Hestenes-Stiefel sum over a delay window, a
    lower bound that a plateau of (P)CG fools, this bounds the error from above. Where round-off
    makes ``U_k - inc_k <= 0`` the recurrence restarts from the cruder bound ``rz_k / mu``.
    """
    U = np.empty(len(rz))
    U[0] = rz[0] / mu
    for k in range(len(rz) - 1):
        t = U[k] - inc[k]
        U[k + 1] = rz[k + 1] * t / (mu * t + rz[k + 1]) if t > 0 else rz[k + 1] / mu
    return U


def stop_iteration(hist: dict, mu: float, fraction: float) -> tuple[int | None, np.ndarray, np.ndarray]:
    """First iterate ``m >= 1`` whose error bound is ``fraction`` x the estimated discretisation error.

    ``eta_m = sqrt(||x_m - x_0||_A^2 / 3)`` with ``||x_m - x_0||_A^2 = sum_{j<m} inc_j`` (the (P)CG
    directions are A-orthogonal): the start interpolates the coarse solution, and Galerkin
    orthogonality on nested spaces with H1 rate 1 gives ``||u_l - u_{l-1}||_A^2 = 3 ||u - u_l||_A^2``;
    the partial sums approach it from below, so ``eta_m`` errs on the safe (small) side. The test
    is ``U_m <= (fraction eta_m)^2`` with ``U`` from :func:`gauss_radau_bounds`.
    Returns ``(m or None, U, eta)``.
    """
    U = gauss_radau_bounds(hist["inc"], hist["rz"], mu)
    eta = np.sqrt(np.concatenate([[0.0], np.cumsum(hist["inc"])]) / 3.0)
    ok = np.flatnonzero(U[1:] <= (fraction * eta[1:]) ** 2)
    return (int(ok[0]) + 1 if ok.size else None), U, eta


def _nested_runs(study, spec, meshes, mesh_times, records, hierarchy=lambda level: None):
    """Nested iteration stopped at a fraction of the estimated discretisation error ((P)CG only).

    Level 0 is solved from zero with the solver's fixed ``rtol``; its converged Lanczos coefficients
    give ``lambda_0``, the smallest Ritz value of ``M^-1 A`` there. On level ``l >= 1`` the start is the
    coarse nested solution interpolated to the refined mesh; an untimed analysis pass
    (:func:`cg_history`) records the coefficients and :func:`stop_iteration` picks the first iterate
    whose Gauss-Radau error bound, with ``mu_l = lambda_0 (h_l / h_0)^2 / 2`` (the smallest
    eigenvalue of a second-order operator decays at worst like ``h^2``: exact for CG and IC(0),
    pessimistic for AMG, whose ``lambda_min`` stays O(1)), is ``fraction`` x the estimated
    discretisation error; the timed run then stops there (``maxiter``), from the same start.
    The record checks the test afterwards: the attained algebraic error
    ``||u_nested - u_l||_A`` (``u_l`` the exact discrete solution, by a direct solve) over the
    energy-norm discretisation error ``||u - u_l||_A`` of the level. ``hierarchy(level)``: the
    nested meshes up to a level, for ``preconditioner: gmg``.
    """
    from ...solvers import solve as _solve_raw

    d = study.spec
    frac = d.stop_fraction
    rule = d.quadrature[0]
    out = []
    systems, exact, problems = [], [], []
    for mesh in meshes:
        prob, K, F = _assemble(spec, mesh, rule)
        problems.append(prob)
        systems.append(prob.reduce(K, F, "pcg"))
        exact.append(_solve_raw(systems[-1].A, systems[-1].b, method="direct").x)
    for s in study.solvers:
        if s.method not in ("cg", "pcg"):
            continue
        label = s.label
        prev = None
        lam0 = h0 = None
        for lvl, mesh in enumerate(meshes):
            sys = systems[lvl]
            mg = _multigrid(s, hierarchy(lvl), sys)
            fixed = next(r for r in records if r["source"] == "femkit" and r["level"] == lvl
                         and r["solver"] == label and r["quadrature"] == rule)
            stop, bound, eta_m, mu = None, None, None, None
            if prev is None:
                x0 = np.zeros(sys.A.shape[0])
                hist = cg_history(sys.A, sys.b, x0, s, mg)
                lam0, h0 = smallest_ritz_value(hist["alpha"], hist["rz"]), fixed["h"]
                tc = time_call(lambda: _solve(sys, s, mg=mg), repeats=d.repeats, warmup=0)
            else:
                x0 = interpolate_nested(meshes[lvl - 1], mesh, prev)[sys.free]
                hist = cg_history(sys.A, sys.b, x0, s, mg)
                mu = lam0 * (fixed["h"] / h0) ** 2 / 2.0
                stop, U, eta = stop_iteration(hist, mu, frac)
                if stop is not None:
                    bound, eta_m = float(np.sqrt(U[stop])), float(eta[stop])
                s_run = s if stop is None else s.replace(maxiter=stop, label=s.label)
                tc = time_call(lambda: _solve(sys, s_run, x0=x0.copy(), mg=mg), repeats=d.repeats, warmup=0)
            res, t_solve = tc.value, tc.min  # min over repeats, like the fixed-rtol runs
            u = sys.expand(res.x)
            prev = u
            errs = spec.errors(problems[lvl], u, d.error_order)
            alg = _energy_norm(sys.A, res.x - exact[lvl])
            disc = _energy_norm_error(problems[lvl].kappa, fixed["H1_semi"])
            out.append({
                "solver": label, "level": lvl, "dofs": fixed["dofs"], "h": fixed["h"],
                "iterations_fixed": fixed["iterations"], "iterations_nested": int(res.iterations),
                "t_solve_fixed": fixed["t_solve"], "t_solve_nested": t_solve,
                "L2_fixed": fixed["L2"], "L2_nested": errs["L2"],
                "H1_fixed": fixed["H1_semi"], "H1_nested": errs["H1_semi"],
                "mu": mu, "error_bound": bound, "estimated_discretisation_error": eta_m,
                "bound_over_estimate": (bound / eta_m) if bound is not None and eta_m else None,
                "algebraic_error_energy": alg, "discretisation_error_energy": disc,
                "algebraic_over_discretisation": (alg / disc) if disc and np.isfinite(disc) else None,
                "stopped_by_estimate": stop is not None, "fraction": frac,
            })
    return out


def _energy_norm_error(kappa, h1_semi: float) -> float:
    """``||u - u_l||_A`` from the H1 seminorm error: ``sqrt(kappa) |u - u_l|_1`` for a constant ``kappa``.

    A piecewise ``kappa`` has no such relation: ``nan`` (the ratio column then stays empty).
    """
    kap = np.asarray(kappa, dtype=float)
    if np.allclose(kap, kap.flat[0]):
        return float(np.sqrt(kap.flat[0]) * h1_semi)
    return float("nan")


def unconverged_note(failed) -> str:
    """The report's note listing runs whose solver did not reach its stopping rule."""
    runs = ", ".join(f"{r['solver']} / {r['quadrature']} level {r['level']} "
                     f"(relative residual {r['relative_residual']:.3g}, {r['iterations']} it)" for r in failed)
    return (f"{len(failed)} run(s) did not converge; their errors contain the algebraic error, so they are "
            f"left out of the fitted rates (still in the tables and figures): {runs}.")


def fit_all(records) -> list[dict]:
    """Fitted rates vs h of every (source, solver, quadrature) line and error norm.

    Only converged runs are fitted: an unconverged run's error is partly algebraic, and a rate
    fitted through it would describe the solver's failure, not the discretisation.
    """
    fits = []
    records = [r for r in records if r.get("converged", True)]
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
