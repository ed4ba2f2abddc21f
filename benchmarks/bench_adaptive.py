"""Time to reach an energy error of 1e-2 on the L-shape: adaptive against uniform refinement.

Run by hand (not in CI)::

    python benchmarks/bench_adaptive.py                      # target 1e-2, PCG + SA-AMG, rtol 1e-8
    python benchmarks/bench_adaptive.py --target 2e-2 --repeat 3 --estimator zz

Problem: ``-lap u = 0`` on the L-shape ``(-1, 1)^2 \\ [0, 1] x [-1, 0]`` with
``u = r^(2/3) sin(2 theta / 3)`` on the boundary (femkit's bundled ``cases/poisson_lshape.yaml``).
Both runs start from the same gmsh mesh (``--h0``) and use the same solver through
:func:`femkit.fem.adaptive.adaptive_solve`: adaptive = estimator + Dörfler marking (``--theta``) +
newest-vertex bisection; uniform = red refinement. Each level's solve starts from the previous
solution interpolated to the new mesh (nested iteration) in both.

Printed: for each run, the first level whose true energy error is ``<= --target``, its dofs and the
wall time from the start of the run to the end of that level (the true-error evaluation excluded).
For uniform refinement also the time of the final level alone (as if the user had guessed the
right mesh at once: the most favourable reading for uniform). Ratio uniform / adaptive; goal >= 10.
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


def lshape_u(x, y):
    return np.hypot(x, y) ** (2 / 3) * np.sin(2 / 3 * np.mod(np.arctan2(y, x), 2 * np.pi))


def lshape_grad(x, y):
    r, t = np.hypot(x, y), np.mod(np.arctan2(y, x), 2 * np.pi)
    with np.errstate(divide="ignore"):
        c = 2 / 3 * r ** (-1 / 3)
    return -c * np.sin(t / 3), c * np.cos(t / 3)


def run(mesh, refinement, args):
    from femkit.fem.adaptive import adaptive_solve, poisson_solver

    solve_on = poisson_solver(1.0, 0.0, dirichlet=[(["boundary"], lshape_u)], method=args.method,
                              preconditioner=args.preconditioner, rtol=args.rtol)
    res = adaptive_solve(solve_on, mesh, theta=args.theta, estimator=args.estimator,
                         refinement=refinement, grad_exact=lshape_grad, max_dofs=args.max_dofs,
                         max_levels=200, target=args.target, target_on="error")
    if not res.target_met:
        raise SystemExit(f"{refinement}: error {res.levels[-1].error:.3e} > target after "
                         f"{res.levels[-1].dofs} dofs ({res.stop_reason}); raise --max-dofs")
    return res.levels[-1], res


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--target", type=float, default=1e-2, help="energy error to reach")
    p.add_argument("--h0", type=float, default=0.25, help="initial gmsh mesh size")
    p.add_argument("--theta", type=float, default=0.5)
    p.add_argument("--estimator", default="residual", choices=["residual", "zz"])
    p.add_argument("--method", default="pcg")
    p.add_argument("--preconditioner", default="amg")
    p.add_argument("--rtol", type=float, default=1e-8)
    p.add_argument("--max-dofs", type=int, default=1_200_000)
    p.add_argument("--repeat", type=int, default=3, help="repeats of the (cheap) adaptive run")
    args = p.parse_args(argv)

    from femkit.mesh import generate

    mesh = generate("l_shape", args.h0)
    run(mesh, "adaptive", args)                     # warm-up: imports, pyamg, numba caches
    times, adaptive = [], None
    for _ in range(args.repeat):
        adaptive, res_a = run(mesh, "adaptive", args)
        times.append(adaptive.elapsed)
    t_adaptive = statistics.median(times)
    t0 = time.perf_counter()
    uniform, res_u = run(mesh, "uniform", args)
    wall_u = time.perf_counter() - t0

    print(f"L-shape, energy error target {args.target:g}, {args.method} + {args.preconditioner} "
          f"rtol {args.rtol:g}, initial mesh h0 = {args.h0} ({mesh.n_triangles} triangles)")
    print(f"{'run':<22}{'levels':>7}{'dofs':>10}{'error':>11}{'estimate':>11}{'eff':>7}{'time [s]':>11}")
    print(f"{'adaptive (' + args.estimator + ')':<22}{adaptive.level + 1:>7}{adaptive.dofs:>10}"
          f"{adaptive.error:>11.3e}{adaptive.estimate:>11.3e}{adaptive.effectivity:>7.3f}{t_adaptive:>11.3f}")
    print(f"{'uniform (all levels)':<22}{uniform.level + 1:>7}{uniform.dofs:>10}"
          f"{uniform.error:>11.3e}{uniform.estimate:>11.3e}{uniform.effectivity:>7.3f}{uniform.elapsed:>11.3f}")
    print(f"{'uniform (last level)':<22}{1:>7}{uniform.dofs:>10}{uniform.error:>11.3e}"
          f"{uniform.estimate:>11.3e}{uniform.effectivity:>7.3f}{uniform.solve_time:>11.3f}")
    print(f"ratio uniform / adaptive: {uniform.elapsed / t_adaptive:.1f}x (all levels), "
          f"{uniform.solve_time / t_adaptive:.1f}x (last level only); goal >= 10x")
    print(f"(adaptive median of {args.repeat}: {', '.join(f'{t:.3f}' for t in times)} s; "
          f"uniform run wall time incl. error evaluation {wall_u:.1f} s)")
    print("levels (dofs, error, time): adaptive",
          [(lv.dofs, round(lv.error, 5), round(lv.elapsed, 3)) for lv in res_a.levels[:adaptive.level + 1]][-4:],
          "uniform", [(lv.dofs, round(lv.error, 5), round(lv.elapsed, 3)) for lv in res_u.levels])


if __name__ == "__main__":
    main()
