"""The stress-case types of a ``stability`` study (:data:`STRESS_CASES`): each one's rows and price.

Each stress case (a file in ``cases/stress/`` or inline) sweeps one parameter (``values``):

Poisson (structured triangulations built from arrays, ``-div(kappa grad u) = f``):
- ``poisson_contrast``: kappa = contrast on the black cells of a 4x4 checkerboard, 1 elsewhere.
- ``poisson_anisotropic``: the rectangle [0, a] x [0, 1] on an n x n grid: triangles of aspect ratio a.
- ``poisson_scaled``: the unit square scaled by s (1e-6 ... 1e6) with u = sin(pi x/s) sin(pi y/s);
  the stopping rule is relative to ||b|| and the error is relative to ||u||, so nothing depends on s.
- ``poisson_degenerate``: one interior grid row moved to within eps*h of the next: slivers of area ~eps.
- ``poisson_fine``: the unit square with ~``dofs`` unknowns (1e6 in the bundled file, small in tests).
- ``poisson_neumann``: pure Neumann, singular K: direct on K (SingularSystemError expected), CG on the
  consistent singular system, CG on an inconsistent one (must not report success), and the fix
  (one node pinned to fix the constant).
Solvers:
- ``cg_residual_drift``: CG on an SPD matrix with eigenvalues 1 ... ``value`` (condition number): the
  recursive residual keeps falling while the true one stalls; both reported.
- ``jacobi_divergence``: Jacobi on the SPD, not diagonally dominant ``I + c (ones - I)``: divergence
  must be reported as not converged, never as an exception or a NaN result.
Dynamics:
- ``dynamics_stiffness``: a two-spring chain (stiffness ``value``, masses 1 and ``mass_ratio``) run
  at dt = factor x dt_crit for each explicit integrator; the measured stability boundary is
  compared with bound / omega_max (2 for Verlet-type, 2 sqrt 2 for RK4).
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ...errors import FemkitError, InstabilityError, SingularSystemError
from ...mesh.structured import structured_mesh
from ...registry import Registry
from ..integrators import oscillator_bound

# ----------------------------------------------------------------------------- meshes

def _poisson_system(mesh, kappa, f, g=0.0):
    """K, F and the reduced system of ``-div(kappa grad u) = f``, ``u = g`` on the whole boundary,
    through the one Poisson pipeline (:class:`femkit.fem.PoissonProblem`)."""
    from ...fem import PoissonProblem

    problem = PoissonProblem(mesh, kappa, f, dirichlet=[(None, g)])
    K, F = problem.assemble_matrices()
    return K, F, problem.reduce(K, F)


def _spec(data: dict):
    from ...solvers import SolverSpec

    return SolverSpec.from_mapping(data)


def _solve_row(A, b, s, *, x_ref=None, maxiter=None):
    """One solver (a :class:`~femkit.solvers.SolverSpec`) on one system: the row of the table."""
    t0 = time.perf_counter()
    try:
        res = s.solve(A, b, maxiter=s.maxiter or maxiter)
    except FemkitError as exc:
        return {"survived": False, "outcome": type(exc).__name__, "detail": str(exc)[:200],
                "time": time.perf_counter() - t0}
    row = {"survived": bool(res.converged), "outcome": res.reason, "iterations": int(res.iterations),
           "relative_residual": float(res.relative_residual), "requested_rtol": s.rtol,
           "recursive_residual": float(res.residuals[-1] / max(res.rhs_norm, 1e-300)) if len(res.residuals) else None,
           "time": time.perf_counter() - t0, "detail": res.message[:200]}
    if x_ref is not None:
        nrm = np.linalg.norm(x_ref)
        row["error"] = float(np.linalg.norm(res.x - x_ref) / nrm) if nrm > 0 else float(np.linalg.norm(res.x))
    return row


def _direct(A, b):
    from ...solvers import solve

    return solve(A, b, method="direct").x


# ----------------------------------------------------------------------------- Poisson cases

def _checker_kappa(mesh, contrast, cells=4):
    c = mesh.centroids()
    black = ((np.floor(c[:, 0] * cells) + np.floor(c[:, 1] * cells)) % 2).astype(bool)
    return np.where(black, float(contrast), 1.0)


def case_poisson(case, solvers, quick_n):
    kind, n = case["type"], case.get("n", quick_n)
    rows = []
    for value in case["values"]:
        if kind == "poisson_contrast":
            mesh = structured_mesh(n, n)
            K, F, sys = _poisson_system(mesh, _checker_kappa(mesh, value), 1.0)
        elif kind == "poisson_anisotropic":
            mesh = structured_mesh(n, n, float(value), 1.0)
            K, F, sys = _poisson_system(mesh, 1.0, 1.0)
        elif kind == "poisson_scaled":
            s = float(value)
            mesh = structured_mesh(n, n, s, s)
            u = lambda x, y, s=s: np.sin(np.pi * x / s) * np.sin(np.pi * y / s)  # noqa: E731
            K, F, sys = _poisson_system(mesh, 1.0, lambda x, y, s=s: 2 * np.pi**2 / s**2 * u(x, y))
        elif kind == "poisson_degenerate":
            mesh = structured_mesh(n, n)
            pts = mesh.points.copy()
            h = 1.0 / n
            row = n // 2
            sel = np.isclose(pts[:, 1], row * h)
            pts[sel, 1] = (row + 1) * h - float(value) * h  # slivers of relative area eps
            interior = sel & (pts[:, 0] > 0) & (pts[:, 0] < 1)
            pts[sel & ~interior, 1] = row * h  # keep the boundary straight
            from ...mesh import Mesh

            mesh = Mesh(points=pts, triangles=mesh.triangles)
            K, F, sys = _poisson_system(mesh, 1.0, 1.0)
        elif kind == "poisson_fine":
            m = max(2, int(round(np.sqrt(float(value)))) + 1)
            mesh = structured_mesh(m, m)
            K, F, sys = _poisson_system(mesh, 1.0, 1.0)
        else:
            raise ValueError(kind)
        if kind == "poisson_fine":
            x_ref = None
        else:
            x_ref = _direct(sys.A, sys.b)
        base = {"case": case["name"], "type": kind, "value": value, "dofs": int(sys.A.shape[0])}
        for s in solvers:
            r = _solve_row(sys.A, sys.b, s, x_ref=x_ref, maxiter=case.get("maxiter"))
            if kind == "poisson_scaled" and "error" in r:
                # discretisation error relative to ||u||: identical at every scale if nothing leaks
                uex = u(*mesh.points.T)
                r["error"] = float(np.linalg.norm(sys.expand(_direct(sys.A, sys.b)) - uex) / np.linalg.norm(uex))
            rows.append({**base, "method": s.label, **r})
    return rows


#: The pure-Neumann case's solvers: CG on the singular system, AMG-PCG once a node is pinned (both
#: to the default ``rtol``, :data:`femkit.solvers.core.defaults.DEFAULT_RTOL`, read when solving).
NEUMANN_CG = {"method": "cg"}
NEUMANN_PINNED = {"method": "pcg", "preconditioner": "amg"}


def case_neumann(case, quick_n):
    from ...fem import PoissonProblem
    from ...solvers import solve

    n = case.get("n", quick_n)
    mesh = structured_mesh(n, n)
    uex = lambda x, y: np.cos(np.pi * x) * np.cos(np.pi * y)  # noqa: E731
    problem = PoissonProblem(mesh, 1.0, lambda x, y: 2 * np.pi**2 * uex(x, y), dirichlet=[],
                             load_rule="gauss3", nullspace="pin", pin_value=float(uex(0.0, 0.0)))
    K, F = problem.assemble_matrices()
    F_cons = F - F.mean()  # exactly consistent: orthogonal to the constant null vector
    F_bad = F_cons + 1.0   # inconsistent
    ue = uex(*mesh.points.T)
    base = {"case": case["name"], "type": "poisson_neumann", "dofs": mesh.n_points}
    rows = []

    def err(x):
        d = (x - x.mean()) - (ue - ue.mean())
        return float(np.linalg.norm(d) / np.linalg.norm(ue - ue.mean()))

    sys = problem.reduce(K, F_cons)  # node 0 pinned to the exact value: SPD
    pinned_err = err(sys.expand(_direct(sys.A, sys.b)))
    t0 = time.perf_counter()
    try:
        x = solve(K, F_cons, method="direct").x
        ok = bool(np.all(np.isfinite(x))) and err(x) <= 2 * pinned_err
        rows.append({**base, "value": "singular K, direct", "method": "direct", "survived": ok,
                     "outcome": "no SingularSystemError; " + ("result finite and accurate up to the constant"
                                                               if ok else "garbage result"),
                     "error": err(x) if np.all(np.isfinite(x)) else None, "time": time.perf_counter() - t0})
    except SingularSystemError as exc:
        rows.append({**base, "value": "singular K, direct", "method": "direct", "survived": True,
                     "outcome": "SingularSystemError (detected)", "detail": str(exc)[:200],
                     "time": time.perf_counter() - t0})
    r = _solve_row(K, F_cons, _spec(NEUMANN_CG), maxiter=case.get("maxiter", 5000))
    if "iterations" in r:
        r["error"] = None
    rows.append({**base, "value": "singular K, consistent rhs", "method": "cg", **r})
    r = _solve_row(K, F_bad, _spec(NEUMANN_CG), maxiter=case.get("maxiter", 2000))
    # surviving here means: not claiming convergence on an unsolvable system
    r["survived"] = not r.get("survived", False)
    r["outcome"] = "reported not converged: " + str(r.get("outcome")) if r["survived"] else "claimed convergence!"
    rows.append({**base, "value": "singular K, inconsistent rhs", "method": "cg", **r})
    # the fix: pin one node (value of the exact solution there) -> SPD
    r = _solve_row(sys.A, sys.b, _spec(NEUMANN_PINNED))
    rows.append({**base, "value": "one node pinned (constant fixed)", "method": "pcg+amg", **r,
                 "error": pinned_err})
    return rows


# ----------------------------------------------------------------------------- solver cases

def case_cg_drift(case):
    import scipy.sparse as sp

    from ...solvers import solve

    rows = []
    n = case.get("n", 300)
    rng = np.random.default_rng(0)
    for kappa in case["values"]:
        # a cluster in [1, 2] and ten outliers up to kappa: CG converges, and the true residual
        # stalls near eps * ||A|| ||x|| / ||b|| while the recursive one keeps falling
        eig = np.concatenate([np.linspace(1.0, 2.0, n - 10), np.geomspace(1e2, float(kappa), 10)])
        Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
        A = sp.csr_matrix((Q * eig) @ Q.T)
        A = (A + A.T) * 0.5
        b = Q @ rng.standard_normal(n)
        t0 = time.perf_counter()
        res = solve(A, b, method="cg", rtol=1e-14, maxiter=case.get("maxiter", 20 * n))
        rec = float(res.residuals[-1] / res.rhs_norm)
        rows.append({"case": case["name"], "type": "cg_residual_drift", "value": kappa, "dofs": n, "method": "cg",
                     "survived": True, "outcome": res.reason, "iterations": int(res.iterations),
                     "relative_residual": float(res.relative_residual), "recursive_residual": rec,
                     "requested_rtol": 1e-14, "converged_flag": bool(res.converged),
                     "drift": float(res.relative_residual / rec) if rec > 0 else None,
                     "time": time.perf_counter() - t0,
                     "detail": "recursive vs true relative residual; 'converged' must follow the true one"})
        rows[-1]["survived"] = bool(res.converged) == bool(res.relative_residual <= 1e-14 * (1 + 1e-12))
    return rows


def case_jacobi(case):
    import scipy.sparse as sp

    from ...solvers import solve

    rows = []
    n = case.get("n", 10)
    for c in case["values"]:
        A = sp.csr_matrix((1 - c) * np.eye(n) + c * np.ones((n, n)))
        b = np.ones(n)
        t0 = time.perf_counter()
        try:
            res = solve(A, b, method="jacobi", rtol=1e-8, maxiter=case.get("maxiter", 200))
            clean = (not res.converged) and np.all(np.isfinite(res.x)) if c * (n - 1) >= 1 else res.converged
            rows.append({"case": case["name"], "type": "jacobi_divergence", "value": c, "dofs": n, "method": "jacobi",
                         "survived": bool(clean), "outcome": res.reason, "iterations": int(res.iterations),
                         "relative_residual": float(res.relative_residual), "time": time.perf_counter() - t0,
                         "detail": f"Jacobi spectral radius {abs(c) * (n - 1):.3g}; {res.message[:150]}"})
        except FemkitError as exc:
            rows.append({"case": case["name"], "type": "jacobi_divergence", "value": c, "dofs": n, "method": "jacobi",
                         "survived": False, "outcome": type(exc).__name__, "detail": str(exc)[:200],
                         "time": time.perf_counter() - t0})
    return rows


# ----------------------------------------------------------------------------- dynamics


#: A run "survived" when the largest total energy of its last third of steps is at most this
#: multiple of the largest of its first third: bounded oscillation (a symplectic method near its
#: limit swings the energy by 1 / (1 - (h w / 2)^2)) passes, exponential growth does not.
ENERGY_FACTOR = 10.0
#: ... and its energy never exceeded this multiple of the initial one (nonlinear springs can
#: saturate an instability early, so growth between thirds alone would miss it).
ENERGY_PEAK = 1e3


def _chain(k, ratio):
    from ...dynamics.system import MassSpringSystem

    x0 = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    return MassSpringSystem(x0, np.array([1.0, 1.0, float(ratio)]), [[0, 1], [1, 2]], float(k), pinned=[0])


def case_dynamics(case, integrators):
    from ...dynamics.simulate import simulate
    from ...dynamics.stability import estimate_omega_max

    factors = case.get("dt_factors", [0.5, 0.9, 0.98, 1.02, 1.1, 2.0])
    steps = int(case.get("t_end", 1000))  # number of steps per run
    rows = []
    for k in case["values"]:
        for ratio in case.get("mass_ratio", [1.0]):
            system = _chain(k, ratio)
            x0 = system.x0.copy()
            x0[2, 0] += 0.01  # small stretch of the outer spring
            w = float(estimate_omega_max(system))
            for spec in integrators:
                label = spec.label
                integ = spec.build()
                if integ.implicit:
                    continue
                for fac in factors:
                    dt = fac * integ.stability_bound / w
                    t0 = time.perf_counter()
                    try:
                        with warnings.catch_warnings():
                            warnings.simplefilter("ignore")
                            tr = simulate(system, integ, dt, steps * dt, x0=x0, record_every=1,
                                          energy_growth_limit=1e3)
                        e = np.abs(tr.energies["total"])
                        third = max(1, len(e) // 3)
                        growth = float(e[-third:].max() / e[:third].max())
                        peak = float(e.max() / e[0])
                        ok = bool(np.isfinite(growth)) and growth <= ENERGY_FACTOR and peak <= ENERGY_PEAK
                        outcome = ("completed" if ok else f"energy grew {growth:.3g} x from the first to the last "
                                   f"third, peak {peak:.3g} x E0")
                        drift = growth
                    except InstabilityError as exc:
                        ok, outcome, drift = False, f"InstabilityError at step {exc.step}", None
                    rows.append({"case": case["name"], "type": "dynamics_stiffness", "value": f"k={k:g}, m2/m1={ratio:g}",
                                 "k": float(k), "mass_ratio": float(ratio), "method": label, "dt": dt,
                                 "dt_factor": fac, "omega_max": w, "h_omega": dt * w,
                                 "bound": oscillator_bound(integ) or 0.0,
                                 "survived": ok, "outcome": outcome, "energy_growth": drift, "time": time.perf_counter() - t0})
    return rows


# ----------------------------------------------------------------------------- stress-case types

@dataclass(frozen=True)
class StressCase:
    """One stress-case ``type``: ``run(case, study, quick_n) -> rows``, the default ``values``
    of its swept parameter and ``price(case, study, quick_n) -> (seconds, runs)``, what the
    study's plan sums (:func:`femkit.study.stability.cost.plan`)."""

    run: Callable
    values: tuple
    price: Callable | None = None


#: stress-case type -> :class:`StressCase`; the ``type`` enum of the schema is its names.
STRESS_CASES: Registry = Registry("stress case type")


def _poisson(case, study, quick_n):
    return case_poisson(case, study.solvers, quick_n)


def _poisson_price(case, study, quick_n):
    """Per value: the mesh's assembly, a direct reference solve, every solver."""
    from ..prices import poisson_run_seconds

    if case["type"] == "poisson_fine":
        sizes = [2 * (max(2, int(round(np.sqrt(float(v)))) + 1)) ** 2 for v in case["values"]]
    else:
        sizes = [2 * case.get("n", quick_n) ** 2] * len(case["values"])
    reference = case["type"] != "poisson_fine"  # the others solve directly for x_ref
    seconds = sum(poisson_run_seconds(t, assemble=True, solve=reference)
                  + sum(poisson_run_seconds(t, s, assemble=False) for s in study.solvers)
                  for t in sizes)
    return seconds, len(sizes) * len(study.solvers)


def _neumann_price(case, study, quick_n):
    from ..prices import poisson_run_seconds

    t = 2 * case.get("n", quick_n) ** 2
    cg, amg = _spec(NEUMANN_CG), _spec(NEUMANN_PINNED)
    return (2 * poisson_run_seconds(t) + 2 * poisson_run_seconds(t, cg, assemble=False)
            + poisson_run_seconds(t, amg, assemble=False)), 4


def _dense_price(case, study, quick_n, n_default, iterations):
    """A dense ``n x n`` system (QR or a matrix product, then ``iterations(n)`` matrix-vector
    products), at ~1 ns per flop."""
    n = case.get("n", n_default)
    flops = 4.0 * n**3 + iterations(n) * 2.0 * n**2
    return len(case["values"]) * flops * 1e-9, len(case["values"])


def _dynamics_price(case, study, quick_n):
    from ..prices import steps_seconds

    factors = case.get("dt_factors", [0.5, 0.9, 0.98, 1.02, 1.1, 2.0])
    explicit = [s for s in study.integrators if not s.build().implicit]
    runs = len(case["values"]) * len(case.get("mass_ratio", [1.0])) * len(explicit) * len(factors)
    return runs * steps_seconds(int(case.get("t_end", 1000)), nodes=3, springs=2), runs


for _name, _values in (("poisson_contrast", (1.0, 1e2, 1e4, 1e6, 1e8)),
                       ("poisson_anisotropic", (1.0, 10.0, 100.0, 1000.0)),
                       ("poisson_scaled", (1e-6, 1.0, 1e6)),
                       ("poisson_degenerate", (1e-2, 1e-4, 1e-6)),
                       ("poisson_fine", (1e6,))):
    STRESS_CASES.register(_name, StressCase(_poisson, _values, _poisson_price))
STRESS_CASES.register("poisson_neumann", StressCase(
    lambda case, study, quick_n: case_neumann(case, quick_n), (0,), _neumann_price))
STRESS_CASES.register("cg_residual_drift", StressCase(
    lambda case, study, quick_n: case_cg_drift(case), (1e4, 1e8, 1e12),
    lambda case, study, quick_n: _dense_price(case, study, quick_n, 300,
                                              lambda n: case.get("maxiter", 20 * n))))
STRESS_CASES.register("jacobi_divergence", StressCase(
    lambda case, study, quick_n: case_jacobi(case), (0.05, 0.5, 0.9),
    lambda case, study, quick_n: _dense_price(case, study, quick_n, 10,
                                              lambda n: case.get("maxiter", 200))))
STRESS_CASES.register("dynamics_stiffness", StressCase(
    lambda case, study, quick_n: case_dynamics(case, study.integrators), (1e2, 1e5, 1e9),
    _dynamics_price))

