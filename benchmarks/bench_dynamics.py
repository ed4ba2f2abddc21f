"""Dynamics benchmark (run by hand): ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_dynamics.py``.

* Liu et al.'s cloth (81 x 81 nodes), fast mass-spring with 10 local/global iterations per
  1/30 s frame (paper: 50 ms/frame in C++; REFERENCE.md: scipy splu, n x n, 3 rhs: 47-67 ms);
* a 128 x 128 cloth (~97k springs): time per step of symplectic Euler, Baraff-Witkin implicit
  Euler (direct) and Newton implicit Euler (direct).

Prints medians over repeats (after a warm-up step, which also pays the one-time factorisation).
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

from femkit.dynamics.forces import Gravity  # noqa: E402
from femkit.dynamics.integrators import StepContext, get_integrator  # noqa: E402
from femkit.dynamics.topology import cloth_grid  # noqa: E402


def _time_steps(system, name, dt, repeats, **opts):
    ctx = StepContext(solver="direct")
    integ = get_integrator(name, **opts)
    s = integ.start(system, system.x0, system.v0, 0.0, dt, ctx)
    t0 = time.perf_counter()
    s = integ.step(system, s, dt, ctx)  # warm-up (one-time factorisation for fast mass-spring)
    first = time.perf_counter() - t0
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        s = integ.step(system, s, dt, ctx)
        times.append(time.perf_counter() - t0)
    return first, statistics.median(times), ctx.stats


def main(quick: bool = False) -> None:
    liu = cloth_grid(81, 81, 1.0, 1.0, k_structural=1e3, k_shear=1e3, k_bending=1e2,
                     total_mass=1.0, pinned="top_corners", forces=[Gravity(9.81)])
    first, med, stats = _time_steps(liu, "fast_mass_spring", 1.0 / 30.0, 3 if quick else 10,
                                    iterations=10)
    print(f"Liu cloth 81x81 ({liu.n_springs} springs), fast mass-spring 10 it: "
          f"{1e3 * med:.1f} ms/frame median (first frame incl. factorisation {1e3 * first:.1f} ms; "
          f"factorizations {stats.get('factorizations')})")

    big = cloth_grid(128, 128, 1.0, 1.0, k_structural=3e4, k_shear=3e4, k_bending=3e4,
                     total_mass=1.0, pinned="top_corners", forces=[Gravity(9.81)])
    print(f"cloth 128x128: {big.n_springs} springs, {big.ndof} dofs")
    for name, dt, reps, opts in (("symplectic_euler", 3.125e-4, 5 if quick else 30, {}),
                                 ("implicit_euler", 1.0 / 60.0, 2 if quick else 5, {}),
                                 ("newton", 1.0 / 60.0, 1 if quick else 3, {"max_iterations": 10})):
        first, med, stats = _time_steps(big, name, dt, reps, **opts)
        extra = ""
        if "newton_iterations" in stats:
            extra = f", Newton iterations/step {stats['newton_iterations']}"
        print(f"  {name:18s} dt={dt:.3g}: {1e3 * med:9.1f} ms/step median{extra}")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
