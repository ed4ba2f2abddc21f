"""Benchmark femkit's solvers against SciPy and pyamg on the 2D 5-point Poisson matrix.

Run by hand (not in CI)::

    python benchmarks/bench_solvers.py                 # n ~ 1e5 and 1e6
    python benchmarks/bench_solvers.py --sizes 316 --repeat 5

Prints, per size, medians over ``--repeat`` runs and the ratios ours / peer:
  * time per CG iteration: femkit ``cg`` vs ``scipy.sparse.linalg.cg`` (fixed iteration count);
  * PCG + AMG (SA and RS) to rtol 1e-8: femkit ``solve(method="pcg", preconditioner=...)`` vs
    pyamg's own ``ml.solve(b, tol=1e-8, accel="cg")``, setup + solve, with iteration counts;
  * IC(0)-PCG (setup, solve, iterations; the numba compile time of the first call separately);
  * the SuperLU direct solve (factorise + solve).
Targets (issue 2): CG per iteration <= 1.2x SciPy; AMG-PCG <= 1.2x pyamg's own solve.
BLAS threads are pinned to 1 before numpy is imported.
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402


def poisson_2d(m: int) -> sp.csr_matrix:
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(m, m), format="csr")
    eye = sp.identity(m, format="csr")
    return (sp.kron(T, eye) + sp.kron(eye, T)).tocsr()


def median_time(fn, repeat: int):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def bench_cg_iteration(A, b, iters, repeat):
    from scipy.sparse.linalg import cg as scipy_cg

    from femkit.solvers import cg

    # rtol tiny so both run exactly `iters` iterations; interleaved repeats
    t_ours, t_sp = [], []
    for _ in range(repeat):
        t, res = median_time(lambda: cg(A, b, rtol=1e-30, maxiter=iters,
                                        stagnation_window=10 * iters), 1)
        assert res.iterations == iters, res.iterations
        t_ours.append(t)
        t_sp.append(median_time(lambda: scipy_cg(A, b, rtol=1e-30, maxiter=iters), 1)[0])
    t_ours, t_sp = statistics.median(t_ours), statistics.median(t_sp)
    spmv, _ = median_time(lambda: A @ b, max(repeat, 5))
    return t_ours / iters, t_sp / iters, spmv


def bench_amg(A, b, flavour, repeat):
    import pyamg

    from femkit.solvers import solve

    build = pyamg.smoothed_aggregation_solver if flavour == "amg_sa" else pyamg.ruge_stuben_solver

    def peer():
        t0 = time.perf_counter()
        ml = build(A)
        t1 = time.perf_counter()
        hist = []
        x = ml.solve(b, tol=1e-8, accel="cg", residuals=hist)
        t2 = time.perf_counter()
        return t1 - t0, t2 - t1, len(hist) - 1, np.linalg.norm(b - A @ x) / np.linalg.norm(b)

    def ours():
        r = solve(A, b, method="pcg", preconditioner=flavour, rtol=1e-8)
        assert r.converged, r.message
        return r.setup_time, r.solve_time, r.iterations, r.relative_residual

    # interleave the two (alternating which goes first) so load drift hits both alike
    runs = {"pyamg": [], "femkit": []}
    for i in range(repeat):
        order = (("pyamg", peer), ("femkit", ours)) if i % 2 == 0 else (("femkit", ours), ("pyamg", peer))
        for label, fn in order:
            runs[label].append(fn())
    rows = {}
    for label, rs in runs.items():
        tot = [s + t for s, t, _, _ in rs]
        k = int(np.argsort(tot)[len(tot) // 2])
        rows[label] = rs[k] + (statistics.median(tot),)
    pair = [(a[0] + a[1]) / (p[0] + p[1]) for a, p in zip(runs["femkit"], runs["pyamg"])]
    rows["pair_ratio"] = statistics.median(pair)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[316, 1000],
                    help="grid sizes m (n = m^2 unknowns); default 316 1000 (~1e5, 1e6)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cg-iters", type=int, default=100)
    ap.add_argument("--skip-direct", action="store_true")
    args = ap.parse_args(argv)

    from femkit.solvers import factorize, solve

    # numba compile (or cache load) of IC(0) on a tiny matrix, reported separately
    t0 = time.perf_counter()
    solve(poisson_2d(4), np.ones(16), method="pcg", preconditioner="ic0")
    print(f"IC(0) first call (numba compile or cache load): {time.perf_counter() - t0:.2f} s")

    for m in args.sizes:
        A = poisson_2d(m)
        n = A.shape[0]
        b = np.random.default_rng(0).standard_normal(n)
        print(f"\n=== 2D Poisson 5-point, n = {n:,} (nnz {A.nnz:,}), repeat {args.repeat} ===")
        ours, peer, spmv = bench_cg_iteration(A, b, args.cg_iters, args.repeat)
        print(f"SpMV A@x: {spmv * 1e3:.2f} ms")
        print(f"CG time/iteration: femkit {ours * 1e3:.3f} ms, scipy {peer * 1e3:.3f} ms, "
              f"ratio {ours / peer:.3f} (target <= 1.2)")
        for flavour in ("amg_sa", "amg_rs"):
            rows = bench_amg(A, b, flavour, args.repeat)
            for label in ("pyamg", "femkit"):
                s, t, it, rr, tot = rows[label]
                print(f"PCG+{flavour} {label:6s}: setup {s:.3f} s + solve {t:.3f} s = "
                      f"{tot:.3f} s, {it} it, true relres {rr:.1e}")
            print(f"PCG+{flavour} ratio femkit/pyamg (setup+solve): medians "
                  f"{rows['femkit'][4] / rows['pyamg'][4]:.3f}, median of paired runs "
                  f"{rows['pair_ratio']:.3f} (target <= 1.2)")
        runs = [solve(A, b, method="pcg", preconditioner="ic0", rtol=1e-8) for _ in range(args.repeat)]
        r = sorted(runs, key=lambda r: r.setup_time + r.solve_time)[len(runs) // 2]
        print(f"PCG+ic0: setup {r.setup_time:.3f} s + solve {r.solve_time:.3f} s, "
              f"{r.iterations} it, converged {r.converged}")
        if not args.skip_direct:
            t_f, F = median_time(lambda: factorize(A), 1 if n > 5e5 else args.repeat)
            t_s, x = median_time(lambda: F.solve(b), args.repeat)
            print(f"direct (SuperLU {F.info['permc_spec']}, symmetric {F.symmetric}): "
                  f"factorise {t_f:.3f} s + solve {t_s:.3f} s, fill {F.info['fill_ratio']:.1f}, "
                  f"relres {np.linalg.norm(b - A @ x) / np.linalg.norm(b):.1e}")


if __name__ == "__main__":
    main()
