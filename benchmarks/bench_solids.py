"""Elastic-solid kernels (run by hand): ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_solids.py [--quick]``.

Gradient + element-wise projected Hessian of a stable neo-Hookean tetrahedral box (~100k
tetrahedra; ``--quick``: ~10k), randomly perturbed, three ways in one run:

* femkit's compiled element pass (:func:`femkit.elements.compiled.element_pass`: Jacobi + Givens-QR
  signed SVD, principal-frame eigensystem, values written straight into the CSR data);
* the same formulas vectorised in plain NumPy (batched ``np.linalg.svd``/``eigh``, ``einsum``,
  one ``np.bincount`` into the same CSR pattern): the honest baseline a user would write;
* the energy alone (femkit), for the cost of the SVD.

Both produce the same matrix (checked, 1e-9 relative) before timing. Median of 3 after a
warm-up; elements per second. Goal (issue): >= 500k elements/s on one core.

``--newton``: one Newton iteration of the ``newton`` integrator (implicit Euler) with the
``cholesky`` solver on a clamped 60 x 12 x 12-cube beam (51,840 tetrahedra): the step with
``max_iterations=1`` (element pass, the matrix written into the free-dof pattern built once,
CHOLMOD's numeric factorisation on the kept symbolic analysis, the solve, the line search) against
its factorisation alone (``ctx.stats["time_factorization"]``), median of 3 after a warm-up step.
Goal (issue): the iteration <= 1.5x its factorisation alone.

``--cantilever``: tip deflection of a clamped 4 x 1 x 1 beam (linear material, E = 1000, nu = 0.3,
tip traction 1e-3) on 4k x k x k cubes, k = 2, 4, 8, 16 (``--quick``: up to 8): the observed order
from the three finest, the Richardson-extrapolated deflection, and Timoshenko's
``P L^3 / (3 E I) + P L / (kappa G A)`` (``kappa = 10 (1 + nu) / (12 + 11 nu)``).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

# the hand-written formulas of the NumPy baseline are the tests' reference
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "solids"))


def numpy_gradient_hessian(body, x, mu, lam):
    """Vectorised NumPy: stable neo-Hookean gradient and projected Hessian (CSR data), from the
    hand-written formulas the tests check femkit against (tests/solids/_reference.py)."""
    from _reference import hand, principal_modes

    r = body.rest
    d = body.dim
    F = np.einsum("mna,mnb->mab", x[r.cells], r.gradients)
    U, s, Vt = np.linalg.svd(F)
    V = np.swapaxes(Vt, 1, 2).copy()
    for M in (U, V):
        neg = np.linalg.det(M) < 0
        M[neg, :, -1] *= -1
        s[neg, -1] *= -1
    _, g, Hs = hand("stable_neo_hookean", s, mu, lam)
    P = np.einsum("mai,mi,mbi->mab", U, g, V)
    vol = r.volumes
    grad = np.zeros_like(x)
    np.add.at(grad, r.cells, vol[:, None, None] * np.einsum("mab,mnb->mna", P, r.gradients))
    L, Q = principal_modes(U, s, V, g, Hs)
    L = np.maximum(L, 0.0)
    W = np.einsum("mkab,mnb->mkna", Q, r.gradients).reshape(len(F), d * d, -1)
    He = np.einsum("m,mk,mki,mkj->mij", vol, L, W, W)          # (m, 12, 12)
    pat = body.pattern
    return grad, np.bincount(_dof_slots(body).ravel(), weights=He.ravel(), minlength=pat.nnz)


def _dof_slots(body, _cache={}):
    """CSR position of every element-matrix entry (built once, not timed)."""
    if id(body) in _cache:
        return _cache[id(body)]
    pat, d, cells = body.pattern, body.dim, body.rest.cells
    nv = d + 1
    r0 = pat.node_indptr[cells]                                # (m, nv)
    width = pat.node_indptr[cells + 1] - r0
    off = pat.node_slots.reshape(-1, nv, nv) - r0[:, :, None]
    a = np.arange(d)
    base = (d * d * r0)[:, :, None, None, None] + a[None, None, :, None, None] * d * width[:, :, None, None, None] \
        + off[:, :, None, :, None] * d + a[None, None, None, None, :]
    slots = base.transpose(0, 1, 2, 3, 4).reshape(len(cells), nv * d, nv * d)
    _cache[id(body)] = slots
    return slots


def _median_time(fn, repeats=3):
    fn()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def newton_iteration(quick: bool) -> None:
    """Time one Newton iteration of the ``newton`` integrator (implicit Euler) on a clamped beam,
    through its own ``cholesky`` path (the matrix written into the pattern built once, CHOLMOD
    refactorising on the kept analysis), against its factorisation alone."""
    import warnings

    from femkit.dynamics.forces import Gravity
    from femkit.dynamics.system import elastic_system
    from femkit.dynamics.integrators import StepContext, get_integrator
    from femkit.mesh.structured import structured_box
    from femkit.solids import ElasticBody, material, tagged_nodes
    from femkit.solvers.spec import SolverSpec

    k = 6 if quick else 12
    mesh = structured_box(5 * k, k, k, (5.0, 1.0, 1.0))
    body = ElasticBody.from_mesh(mesh, material("stable_neo_hookean", E=1e5, nu=0.3, density=1e3))
    system = elastic_system(body, pinned=tagged_nodes(mesh, "xmin"), forces=[Gravity(9.81)])
    x = mesh.points.copy()
    x[:, 2] -= 0.01 * x[:, 0] ** 2
    one = get_integrator("newton", max_iterations=1)        # one iteration per call
    ctx = StepContext(SolverSpec("cholesky"))
    state = one.start(system, x, np.zeros_like(x), 0.0, 1e-2, ctx)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                      # "stopped at max_iterations"
        one.step(system, state, 1e-2, ctx)                   # pattern, analysis, compilation
        rows = []
        for _ in range(3):
            before = ctx.stats.get("time_factorization", 0.0)
            t0 = time.perf_counter()
            one.step(system, state, 1e-2, ctx)
            total = time.perf_counter() - t0
            rows.append((total, ctx.stats["time_factorization"] - before))
    total, factor = sorted(rows)[1]                          # the median run
    t0 = time.perf_counter()
    body.evaluate(x, 2, project=True)
    element = time.perf_counter() - t0
    print(f"\nNewton iteration (newton integrator, cholesky: CHOLMOD): {mesh.n_cells} tetrahedra, "
          f"{len(system.free_dofs)} free dofs, symbolic analyses reused "
          f"{ctx.stats.get('symbolic_reuses', 0)} of {ctx.stats['factorizations']}")
    print(f"{'element pass (gradient + projected Hessian)':44s} {element:8.3f} s")
    print(f"{'factorisation (numeric, kept analysis)':44s} {factor:8.3f} s")
    print(f"{'the whole iteration':44s} {total:8.3f} s  = {total / factor:.2f}x the factorisation")


def cantilever(quick: bool) -> None:
    """Tip deflection under refinement against Timoshenko beam theory."""
    from femkit.mesh.structured import structured_box
    from femkit.solids import (Dirichlet, ElasticBody, material, solve_static, tagged_facets,
                               tagged_nodes, traction_forces)

    E, nu, L, q = 1000.0, 0.3, 4.0, 1e-3
    mat = material("linear", E=E, nu=nu)
    hs, ws = [], []
    for k in ((1, 2, 4, 8) if quick else (2, 4, 8, 16)):
        t0 = time.perf_counter()
        mesh = structured_box(4 * k, k, k, (L, 1.0, 1.0))
        body = ElasticBody.from_mesh(mesh, mat)
        bc = Dirichlet(body.n, 3).fix(tagged_nodes(mesh, "xmin"))
        f = traction_forces(mesh.points, tagged_facets(mesh, "xmax"), [0.0, 0.0, -q])
        u = solve_static(body, bc, f, project=False).u
        hs.append(1.0 / k)
        ws.append(-u[tagged_nodes(mesh, "xmax"), 2].mean())
        print(f"k = {k:2d}: {mesh.n_cells:6d} tetrahedra, tip deflection {ws[-1]:.6e} "
              f"({time.perf_counter() - t0:.1f} s)")
    G, inertia, kappa = E / (2 * (1 + nu)), 1.0 / 12.0, 10 * (1 + nu) / (12 + 11 * nu)
    w_t = q * L**3 / (3 * E * inertia) + q * L / (kappa * G)
    w = np.array(ws)
    order = np.log((w[-3] - w[-2]) / (w[-2] - w[-1])) / np.log(2.0)
    w_inf = w[-1] + (w[-1] - w[-2]) / (2.0**order - 1.0)
    slope = np.polyfit(np.log(hs), np.log(np.abs(w - w_inf)), 1)[0]
    print(f"observed order {order:.2f} (fitted slope of |w_h - w_inf| {slope:.2f}); extrapolated "
          f"{w_inf:.6e}; Timoshenko {w_t:.6e} (extrapolated / Timoshenko - 1 = {w_inf / w_t - 1:+.3f})")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--newton", action="store_true", help="time one implicit-Euler Newton iteration")
    ap.add_argument("--cantilever", action="store_true", help="tip deflection against beam theory")
    args = ap.parse_args(argv)
    if args.cantilever:
        cantilever(args.quick)
        return
    if args.newton:
        newton_iteration(args.quick)
        return
    from femkit.mesh.structured import structured_box
    from femkit.solids import ElasticBody, material

    n = (12, 12, 12) if args.quick else (30, 30, 19)
    mesh = structured_box(*n)
    mat = material("stable_neo_hookean", E=1e3, nu=0.3)
    body = ElasticBody.from_mesh(mesh, mat)
    rng = np.random.default_rng(0)
    h = 1.0 / max(n)
    x = mesh.points + 0.1 * h * rng.standard_normal(mesh.points.shape)
    m = mesh.n_cells
    _, g, H, _ = body.evaluate(x, 2, project=True)
    g_np, data_np = numpy_gradient_hessian(body, x, mat.mu, mat.lam)
    err = max(np.abs(g - g_np).max() / np.abs(g).max(), np.abs(H.data - data_np).max() / np.abs(H.data).max())
    assert err < 1e-9, err
    rows = [("femkit compiled: gradient + projected Hessian", _median_time(lambda: body.evaluate(x, 2, project=True))),
            ("NumPy vectorised: the same", _median_time(lambda: numpy_gradient_hessian(body, x, mat.mu, mat.lam))),
            ("femkit compiled: energy only", _median_time(lambda: body.evaluate(x, 0)))]
    print(f"{m} tetrahedra, {mesh.n_points} nodes, stable neo-Hookean; agreement {err:.1e}")
    print(f"{'what':48s} {'seconds':>9s} {'k elements/s':>13s}")
    for name, t in rows:
        print(f"{name:48s} {t:9.3f} {m / t / 1e3:13.0f}")
    print(f"speed-up over NumPy: {rows[1][1] / rows[0][1]:.1f}x")


if __name__ == "__main__":
    main()
