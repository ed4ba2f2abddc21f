"""Benchmark the PETSc backend against serial femkit on a ~2M-unknown P1 Poisson problem.

Run by hand (not in CI), with the PETSc environment of scripts/install-petsc.sh::

    .venv-petsc/bin/python benchmarks/bench_petsc.py              # refine 6: ~1.9M unknowns
    .venv-petsc/bin/python benchmarks/bench_petsc.py --levels 4   # ~120k unknowns, quick

Problem: -lap u = 1 on the unit square, u = 0 on the boundary, on a gmsh mesh (h = 0.05)
uniformly refined ``--levels`` times (``femkit.mesh.refine``), rtol 1e-8. Rows, each in its
own process (so peak memory is per run):

- serial femkit, PCG + ``amg_rs`` (pyamg Ruge-Stueben);
- PETSc backend on 1 and 2 ranks (``mpirun -n N``), PCG + ``amg`` (hypre BoomerAMG) and
  PCG + ``amg_sa`` (GAMG).

Last line: the COO assembly split into local matrices, pattern and values (one process).
Per row: mesh (generate + refine on rank 0, broadcast), partition, assembly (COO pattern +
stiffness values + load + Dirichlet elimination; serial: pattern + stiffness + load + Dirichlet), setup (AMG hierarchy), solve, iterations, and peak resident memory per
rank (``ru_maxrss``). Times are the maximum over ranks. BLAS threads are pinned to 1.
On a 2-core machine 2 ranks use both cores: compare ratios measured in the same run.
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import resource  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def make_mesh(levels: int):
    from femkit.mesh import generate, refine

    return refine(generate("unit_square", 0.05), levels)


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def worker_serial(levels: int, rtol: float) -> dict:
    from femkit.fem import PoissonProblem

    t0 = time.perf_counter()
    mesh = make_mesh(levels)
    t_mesh = time.perf_counter() - t0
    prob = PoissonProblem(mesh, 1.0, 1.0, dirichlet=[(["boundary"], 0.0)])
    t0 = time.perf_counter()
    system = prob.assemble("pcg")
    t_asm = time.perf_counter() - t0
    u, res = prob.solve("pcg", "amg_rs", rtol=rtol)
    return {"row": "serial femkit pcg+amg_rs", "ranks": 1, "unknowns": len(system.free),
            "mesh": t_mesh, "partition": 0.0, "assembly": t_asm, "setup": res.setup_time,
            "solve": res.solve_time, "iterations": res.iterations, "converged": res.converged,
            "peak_mb": [peak_mb()], "u_max": float(u.max())}


def worker_petsc(levels: int, rtol: float, pc: str) -> dict | None:
    from femkit.fem import PoissonProblem
    from femkit.solvers.petsc import require_petsc
    from femkit.solvers.petsc.failure import abort_on_error
    from femkit.fem.distributed.poisson import broadcast_mesh, solve_poisson

    PETSc = require_petsc()
    comm = PETSc.COMM_WORLD
    mpi = comm.tompi4py()
    with abort_on_error(mpi):
        t0 = time.perf_counter()
        mesh = broadcast_mesh(lambda: make_mesh(levels), comm)
        t_mesh = mpi.allreduce(time.perf_counter() - t0, op=_max())
        prob = PoissonProblem(mesh, 1.0, 1.0, dirichlet=[(["boundary"], 0.0)])
        sol = solve_poisson(prob, method="pcg", preconditioner=pc, rtol=rtol, gather=True)
        peaks = mpi.gather(peak_mb(), root=0)
        if comm.getRank() != 0:
            return None
        t = sol.timings
        r = sol.result
        return {"row": f"petsc pcg+{pc} ({r.info['pc_type']})", "ranks": comm.getSize(),
                "unknowns": int(sum(sol.partition["unknowns_per_rank"])), "mesh": t_mesh,
                "partition": t.get("partition", 0.0),
                "assembly": sum(t.get(k, 0.0) for k in ("pattern", "stiffness", "load", "dirichlet")),
                "setup": t["setup"], "solve": t["solve"], "iterations": r.iterations,
                "converged": r.converged, "peak_mb": peaks, "u_max": float(sol.u.max())}


def coo_split(levels: int) -> str:
    """The COO assembly's parts on one process: local matrices (numpy), the pattern
    (MatSetPreallocationCOO, once) and the values (MatSetValuesCOO, min of 3 repeats)."""
    import numpy as np

    from femkit.fem import local_stiffness
    from femkit.solvers.petsc import coo, require_petsc

    PETSc = require_petsc()
    mesh = make_mesh(levels)
    t0 = time.perf_counter()
    local = local_stiffness(mesh, 1.0)
    t_local = time.perf_counter() - t0
    d = mesh.triangles.astype(PETSc.IntType)
    n = mesh.n_points
    A = PETSc.Mat().create(comm=PETSc.COMM_SELF)
    A.setSizes(((n, n), (n, n)))
    A.setType("aij")
    t0 = time.perf_counter()
    coo.set_pattern(A, np.repeat(d, 3, axis=1).ravel(), np.tile(d, (1, 3)).ravel())
    t_pattern = time.perf_counter() - t0
    t_values = []
    for _ in range(3):
        t0 = time.perf_counter()
        coo.set_values(A, local.reshape(-1))
        t_values.append(time.perf_counter() - t0)
    return (f"COO assembly, one process, {local.size:,} triplets: local matrices {t_local:.3f} s, "
            f"pattern (MatSetPreallocationCOO, once) {t_pattern:.3f} s, values "
            f"(MatSetValuesCOO) {min(t_values):.3f} s")


def _max():
    from mpi4py import MPI

    return MPI.MAX


def run_row(args, extra: list[str], ranks: int | None) -> dict:
    cmd = [sys.executable, __file__, "--levels", str(args.levels), "--rtol", str(args.rtol)] + extra
    if ranks is not None:
        cmd = [shutil.which("mpirun") or "mpirun", "--allow-run-as-root", "--oversubscribe",
               "-n", str(ranks)] + cmd
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=int, default=6, help="refinements of the h=0.05 mesh (6: ~1.9M unknowns)")
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--worker", choices=["serial", "petsc", "coo"], help=argparse.SUPPRESS)
    ap.add_argument("--pc", default="amg", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker == "serial":
        print(json.dumps(worker_serial(args.levels, args.rtol)))
        return
    if args.worker == "coo":
        print(json.dumps({"line": coo_split(args.levels)}))
        return
    if args.worker == "petsc":
        out = worker_petsc(args.levels, args.rtol, args.pc)
        if out is not None:
            print(json.dumps(out))
        return
    rows = [run_row(args, ["--worker", "serial"], None)]
    for pc in ("amg", "amg_sa"):
        for n in args.ranks:
            rows.append(run_row(args, ["--worker", "petsc", "--pc", pc], n))
    base = rows[0]
    print(f"-lap u = 1 on the unit square, {base['unknowns']:,} unknowns, rtol {args.rtol:g}; "
          f"times in s (max over ranks), peak memory per rank in MB")
    head = (f"{'row':34s} {'ranks':>5s} {'mesh':>6s} {'part':>6s} {'assem':>6s} {'setup':>6s} "
            f"{'solve':>6s} {'its':>4s} {'setup+solve / serial':>21s}  peak MB per rank")
    print(head)
    ref = base["setup"] + base["solve"]
    for r in rows:
        ratio = (r["setup"] + r["solve"]) / ref
        print(f"{r['row']:34s} {r['ranks']:5d} {r['mesh']:6.2f} {r['partition']:6.2f} "
              f"{r['assembly']:6.2f} {r['setup']:6.2f} {r['solve']:6.2f} {r['iterations']:4d} "
              f"{ratio:21.2f}  {', '.join(f'{m:.0f}' for m in r['peak_mb'])}"
              f"{'' if r['converged'] else '  NOT CONVERGED'}")
        assert abs(r["u_max"] - base["u_max"]) <= 1e-6 * abs(base["u_max"]), (r["row"], r["u_max"])
    print(run_row(args, ["--worker", "coo"], None)["line"])


if __name__ == "__main__":
    main()
