"""Time to the discretisation error: femkit fmg, gmg-PCG, amg_rs-PCG vs pyamg RS and SA.

Run by hand (not in CI)::

    python benchmarks/bench_multigrid.py                   # refinements 8 and 9: ~0.46M, ~1.8M unknowns
    python benchmarks/bench_multigrid.py --levels 8 9 10   # + ~7.3M (needs ~10 GB, a quiet machine)
    python benchmarks/bench_multigrid.py --memory 8        # peak RSS of whole runs, ~2.2M unknowns
    python benchmarks/bench_multigrid.py --vcycle          # V(2,2) factors vs omega, 3 and 7 levels
    python benchmarks/bench_multigrid.py --locality 9      # numbering: none vs rcm

Problem: ``-Laplace u = f`` on the unit square, ``u = sin(pi x) sin(pi y)``, homogeneous Dirichlet,
P1 on a gmsh mesh (h = 0.5) refined uniformly ``k`` times; every solver gets the same matrix.

"Time to discretisation error": the discrete solution ``u_h`` is computed first (gmg-PCG, rtol
1e-12); for each PCG-type solver the first rtol of 1e-1, 1e-2, ... whose max-nodal error is within
1.1x of ``u_h``'s is found (untimed), then setup and solve at that rtol are timed, interleaved over
``--repeat`` rounds (medians). fmg stops by its own estimate (no rtol). Times are also given in
units of one SpMV ``A @ x`` of the same run; peak memory is the tracemalloc peak of setup + solve
(numpy/scipy/pyamg arrays), measured in a separate untimed run. pyamg: ``ruge_stuben_solver`` /
``smoothed_aggregation_solver`` with defaults, ``ml.solve(b, tol=rtol, accel="cg")``. femkit runs
skip the one-off symmetry check (pyamg has none). BLAS threads are pinned to 1.

``--memory k`` compares the peak RSS of two whole runs in fresh processes on the same mesh (gmsh
unit square h = 0.2 refined k times; k = 8: ~2.2M unknowns): ``femkit solve`` of an fmg case file
against scikit-fem (basis, assembly, condense) + pyamg RS-PCG.
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402

import numpy as np  # noqa: E402

PI = np.pi
RTOLS = [10.0 ** -k for k in range(1, 13)]


def exact(x, y):
    return np.sin(PI * x) * np.sin(PI * y)


def source(x, y):
    return 2 * PI * PI * np.sin(PI * x) * np.sin(PI * y)


def problem(levels: int, renumber: str = "none"):
    from femkit.fem import apply_dirichlet, assemble_load, assemble_stiffness
    from femkit.mesh import MeshHierarchy, boundary_nodes, generate

    t0 = time.perf_counter()
    H = MeshHierarchy.from_refinement(generate("unit_square", 0.5), levels, renumber=renumber)
    t1 = time.perf_counter()
    m = H.finest
    sys_ = apply_dirichlet(assemble_stiffness(m), assemble_load(m, source), boundary_nodes(m), 0.0)
    t2 = time.perf_counter()
    return H, sys_, t1 - t0, t2 - t1


def spmv_time(A, repeat=10):
    x = np.random.default_rng(0).standard_normal(A.shape[0])
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        A @ x
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


class Solver:
    """A named solver with separate ``setup()`` and ``solve(rtol)`` (returns x, iterations)."""

    def __init__(self, name, setup, solve):
        self.name, self._setup, self._solve, self.state = name, setup, solve, None

    def setup(self):
        self.state = self._setup()

    def solve(self, rtol):
        return self._solve(self.state, rtol)


def solvers(H, sys_):
    import pyamg

    from femkit.solvers import pcg
    from femkit.solvers.fmg import fmg
    from femkit.solvers import gmg
    from femkit.solvers.preconditioners import amg

    A, b, free = sys_.A, sys_.b, sys_.free

    def pcg_solve(M, rtol):
        r = pcg(A, b, M=M, rtol=rtol, check_symmetry=False)
        return r.x, r.iterations

    def pyamg_solve(ml, rtol):
        hist = []
        x = ml.solve(b, tol=rtol, accel="cg", residuals=hist)
        return x, len(hist) - 1

    def fmg_setup():
        return gmg.build(A, hierarchy=H, free=free)

    def fmg_solve(M, rtol):
        r = fmg(A, b, M=M, check_symmetry=False)
        return r.x, r.iterations, r

    return [
        Solver("femkit fmg", fmg_setup, fmg_solve),
        Solver("femkit gmg-PCG", lambda: gmg.build(A, hierarchy=H, free=free), pcg_solve),
        Solver("femkit amg_rs-PCG", lambda: amg.build_rs(A), pcg_solve),
        Solver("pyamg RS (cg)", lambda: pyamg.ruge_stuben_solver(A), pyamg_solve),
        Solver("pyamg SA (cg)", lambda: pyamg.smoothed_aggregation_solver(A), pyamg_solve),
    ]


def max_nodal(sys_, mesh, x):
    return float(np.abs(sys_.expand(x) - exact(*mesh.points.T)).max())


def bench(levels: int, repeat: int, renumber: str = "none"):
    from femkit.solvers import pcg
    from femkit.solvers import gmg

    H, sys_, t_h, t_asm = problem(levels, renumber)
    A, b, mesh = sys_.A, sys_.b, H.finest
    n = A.shape[0]
    spmv = spmv_time(A)
    print(f"\n=== unit square, {levels} refinements, renumbering {renumber}: n = {n:,} unknowns, "
          f"nnz {A.nnz:,}; "
          f"hierarchy {t_h:.2f} s, assembly + Dirichlet {t_asm:.2f} s; SpMV {spmv * 1e3:.2f} ms ===")
    M = gmg.build(A, hierarchy=H, free=sys_.free)
    ref = pcg(A, b, M=M, rtol=1e-12, check_symmetry=False)
    e_disc = max_nodal(sys_, mesh, ref.x)
    print(f"discrete solution: max-nodal error {e_disc:.4e} (gmg-PCG rtol 1e-12, {ref.iterations} it)")
    del M
    rows = {}
    sol = solvers(H, sys_)
    # untimed: choose each PCG-type solver's rtol; fmg has its own stop
    for s in sol:
        s.setup()
        if s.name == "femkit fmg":
            rows[s.name] = {"rtol": None}
            continue
        for rtol in RTOLS:
            x, _ = s.solve(rtol)
            if max_nodal(sys_, mesh, x) <= 1.1 * e_disc:
                rows[s.name] = {"rtol": rtol}
                break
        else:
            rows[s.name] = {"rtol": RTOLS[-1]}
        s.state = None
    # timed, interleaved (rotating the order every round)
    runs = {s.name: [] for s in sol}
    spmvs = [spmv]
    for rnd in range(repeat):
        spmvs.append(spmv_time(A))  # the unit, measured in every round (the load drifts)
        order = sol[rnd % len(sol):] + sol[:rnd % len(sol)]
        for s in order:
            t0 = time.perf_counter()
            s.setup()
            t1 = time.perf_counter()
            out = s.solve(rows[s.name]["rtol"])
            t2 = time.perf_counter()
            runs[s.name].append((t1 - t0, t2 - t1, out[1], max_nodal(sys_, mesh, out[0]),
                                 out[2] if len(out) > 2 else None))
            s.state = None
    # peak memory (separate, untimed)
    for s in sol:
        tracemalloc.start()
        s.setup()
        s.solve(rows[s.name]["rtol"])
        rows[s.name]["peak_mb"] = tracemalloc.get_traced_memory()[1] / 2 ** 20
        tracemalloc.stop()
        s.state = None
    for name, rs in runs.items():
        rows[name].update(setup=statistics.median(r[0] for r in rs),
                          solve=statistics.median(r[1] for r in rs), iters=rs[-1][2],
                          err=rs[-1][3] / e_disc, res=rs[-1][4])
    spmv = statistics.median(spmvs)
    print(f"SpMV (median over the rounds) {spmv * 1e3:.2f} ms")
    rs_total = rows["pyamg RS (cg)"]["setup"] + rows["pyamg RS (cg)"]["solve"]
    print(f"{'solver':20s} {'rtol':>7s} {'it':>4s} {'setup s':>8s} {'solve s':>8s} {'total s':>8s} "
          f"{'SpMV(solve)':>11s} {'SpMV(total)':>11s} {'us/unknown':>10s} {'/ pyamg RS':>10s} "
          f"{'err/disc':>8s} {'peak MB':>8s}")
    for name, r in rows.items():
        tot = r["setup"] + r["solve"]
        rtol = "own" if r["rtol"] is None else f"{r['rtol']:.0e}"
        print(f"{name:20s} {rtol:>7s} {r['iters']:4d} {r['setup']:8.3f} {r['solve']:8.3f} "
              f"{tot:8.3f} {r['solve'] / spmv:11.1f} {tot / spmv:11.1f} {tot / n * 1e6:10.3f} "
              f"{tot / rs_total:10.3f} {r['err']:8.3f} {r['peak_mb']:8.1f}")
    f = rows["femkit fmg"]["res"]
    if f is not None:
        print(f"fmg: cycles per level {f.info['cycles_per_level']}, stopped by {f.info['stopped_by']}, "
              f"algebraic/discretisation estimate "
              f"{f.info['algebraic_error_estimate'] / f.info['discretisation_error_estimate']:.3f}, "
              f"operator complexity {f.info['operator_complexity']:.3f}")
    return rows, n


def locality(levels: int, repeat: int):
    """Red refinement numbers a level's coarse nodes first and its edge midpoints after them, so
    neighbours end up far apart in memory; compare with reverse Cuthill-McKee on every level."""
    from femkit.fem import apply_dirichlet, assemble_load, assemble_stiffness
    from femkit.mesh import MeshHierarchy, boundary_nodes, generate
    from femkit.solvers.fmg import fmg
    from femkit.solvers import gmg

    coarse = generate("unit_square", 0.5)
    rows = {}
    for rnd in range(repeat):
        for ren in (("none", "rcm") if rnd % 2 == 0 else ("rcm", "none")):
            t0 = time.perf_counter()
            H = MeshHierarchy.from_refinement(coarse, levels, renumber=ren)
            t1 = time.perf_counter()
            m = H.finest
            K = assemble_stiffness(m)
            F = assemble_load(m, source)
            t2 = time.perf_counter()
            s = apply_dirichlet(K, F, boundary_nodes(m), 0.0)
            spmv = spmv_time(s.A, 5)
            M = gmg.build(s.A, hierarchy=H, free=s.free)
            t3 = time.perf_counter()
            M(s.b)
            t4 = time.perf_counter()
            r = fmg(s.A, s.b, M=M, check_symmetry=False)
            t5 = time.perf_counter()
            rows.setdefault(ren, []).append((t1 - t0, t2 - t1, spmv, t4 - t3, t5 - t4, m.n_triangles))
            del H, m, K, F, s, M, r
    print(f"\n=== numbering, {levels} refinements ({rows['none'][0][5]:,} elements), medians of {repeat} ===")
    print(f"{'numbering':10s} {'hierarchy s':>11s} {'assembly s':>10s} {'SpMV ms':>8s} {'V-cycle ms':>10s} {'fmg s':>7s}")
    med = {ren: [statistics.median(r[i] for r in rs) for i in range(5)] for ren, rs in rows.items()}
    for ren, v in med.items():
        print(f"{ren:10s} {v[0]:11.3f} {v[1]:10.3f} {v[2] * 1e3:8.2f} {v[3] * 1e3:10.1f} {v[4]:7.3f}")
    print("ratio none / rcm: " + ", ".join(
        f"{k} {a / b:.2f}x" for k, a, b in zip(["hierarchy", "assembly", "SpMV", "V-cycle", "fmg"],
                                                med["none"], med["rcm"])))


CASE = """problem: poisson
name: memory_fmg
mesh: {{geometry: unit_square, h: {h}, refine: {k}}}
coefficient: 1.0
source: "2 * pi**2 * sin(pi * x) * sin(pi * y)"
boundary:
  dirichlet:
    - {{tags: [boundary], value: 0}}
quadrature: {{load: barycentric}}
solver: {{method: fmg}}
output: {{dir: out, vtu: false, plot: false}}
"""

SAVE_MESH = """
import numpy as np
from femkit.mesh import generate, refine
m = refine(generate("unit_square", {h}), {k})
np.savez({path!r}, points=m.points, triangles=m.triangles)
"""

SKFEM_PIPELINE = """
import numpy as np, time
import pyamg
from skfem import Basis, BilinearForm, ElementTriP1, LinearForm, MeshTri, condense
from skfem.helpers import dot, grad
t0 = time.perf_counter()
d = np.load({path!r})
m = MeshTri(d["points"].T.copy(), d["triangles"].T.copy(), sort_t=False)
del d
basis = Basis(m, ElementTriP1())
lap = BilinearForm(lambda u, v, w: dot(grad(u), grad(v)))
load = LinearForm(lambda v, w: 2 * np.pi ** 2 * np.sin(np.pi * w.x[0]) * np.sin(np.pi * w.x[1]) * v)
A, b = lap.assemble(basis), load.assemble(basis)
Ac, bc, xc, I = condense(A, b, D=basis.get_dofs())
ml = pyamg.ruge_stuben_solver(Ac.tocsr())
x = ml.solve(bc, tol=1e-8, accel="cg")
print(Ac.shape[0], time.perf_counter() - t0)
"""

MEASURE = """
import resource, subprocess, sys, time
t0 = time.perf_counter()
p = subprocess.run(sys.argv[1:], capture_output=True, text=True)
assert p.returncode == 0, p.stderr
print(p.stdout.strip().splitlines()[-1] if p.stdout.strip() else "",
      "|", time.perf_counter() - t0, "|", resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024)
"""


def memory(k: int, h: float = 0.2):
    """Peak RSS of two whole runs on the same mesh (gmsh unit square ``h`` refined ``k`` times),
    each in a fresh process: ``femkit solve`` of an fmg case file (mesh generation, hierarchy,
    assembly of every level, fmg, result.json) against scikit-fem (basis, assembly, condense) +
    pyamg RS-PCG (rtol 1e-8) reading the mesh from a file written beforehand (not measured)."""
    import tempfile
    from pathlib import Path

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    with tempfile.TemporaryDirectory() as tmp:
        case = Path(tmp) / "case.yaml"
        case.write_text(CASE.format(h=h, k=k))
        mesh = str(Path(tmp) / "mesh.npz")
        subprocess.run([sys.executable, "-c", SAVE_MESH.format(h=h, k=k, path=mesh)], env=env,
                       check=True)
        runs = {
            "femkit solve (fmg)": [sys.executable, "-m", "femkit.cli", "solve", str(case), "-q"],
            "scikit-fem + pyamg RS": [sys.executable, "-c", SKFEM_PIPELINE.format(path=mesh)],
        }
        out = {}
        for label, cmd in runs.items():
            res = subprocess.run([sys.executable, "-c", MEASURE] + cmd, capture_output=True,
                                 text=True, env=env, cwd=tmp, check=True).stdout.split("|")
            out[label] = (float(res[1]), float(res[2]))
        import json

        dofs = json.loads((Path(tmp) / "out" / "result.json").read_text())["dofs"]
    print(f"\n=== peak RSS of the whole run, unit square h = {h} refined {k} times, "
          f"{dofs:,} unknowns (fresh processes) ===")
    for label, (t, mb) in out.items():
        print(f"{label:24s} wall {t:7.2f} s, peak RSS {mb:7.0f} MB")
    a, b = out["femkit solve (fmg)"][1], out["scikit-fem + pyamg RS"][1]
    print(f"ratio femkit / scikit-fem+pyamg: {a / b:.3f} (goal < 1)")


def vcycle_factors(omegas, levels=(3, 7), steps: int = 30):
    """Asymptotic energy-norm contraction of the V(2,2)-cycle's error propagator ``I - M A``
    (power iteration) on gmsh meshes (h = 0.5) of the unit square, L-shape and annulus, for each
    relaxation factor and number of levels (meshes): the table of docs/methods.md, section 5."""

    from femkit.fem import apply_dirichlet, assemble_stiffness
    from femkit.mesh import MeshHierarchy, boundary_nodes, generate
    from femkit.solvers.gmg import Multigrid

    print(f"\n=== V(2,2) energy-norm factor, {steps} power steps ===")
    print(f"{'geometry':12s} {'levels':>6s} " + " ".join(f"{'w=' + str(w):>7s}" for w in omegas))
    for geometry in ("unit_square", "l_shape", "annulus"):
        for nlev in levels:
            H = MeshHierarchy.from_refinement(generate(geometry, 0.5), nlev - 1)
            m = H.finest
            s = apply_dirichlet(assemble_stiffness(m), np.zeros(m.n_points), boundary_nodes(m), 0.0)
            row = []
            for w in omegas:
                row.append(Multigrid(s.A, H, free=s.free, omega=w).contraction(steps))
            print(f"{geometry:12s} {nlev:6d} " + " ".join(f"{r:7.3f}" for r in row))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[8, 9],
                    help="refinements of the h = 0.5 gmsh square (8: 0.46M, 9: 1.8M, 10: 7.3M unknowns)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--renumber", choices=["none", "rcm"], default="rcm",
                    help="node numbering of every level (default rcm: reverse Cuthill-McKee)")
    ap.add_argument("--locality", type=int, default=None, metavar="K",
                    help="only compare numberings at K refinements: hierarchy, first-call "
                         "assembly, SpMV, one V-cycle, fmg")
    ap.add_argument("--vcycle", action="store_true",
                    help="only print V(2,2) factors for --omegas at 3 and 7 levels")
    ap.add_argument("--omegas", type=float, nargs="+", default=[1.0, 1.1, 1.2, 1.25, 1.3])
    ap.add_argument("--memory", type=int, default=None, metavar="K",
                    help="only compare the peak RSS of whole runs at K refinements of h = 0.2")
    args = ap.parse_args(argv)
    if args.memory is not None:
        memory(args.memory)
        return
    if args.locality is not None:
        locality(args.locality, args.repeat)
        return
    if args.vcycle:
        vcycle_factors(args.omegas)
        return
    per_unknown = {}
    for k in args.levels:
        rows, n = bench(k, args.repeat, args.renumber)
        r = rows["femkit fmg"]
        per_unknown[n] = (r["setup"] + r["solve"]) / n
    if len(per_unknown) > 1:
        base = per_unknown[min(per_unknown)]
        print("\nfmg time per unknown (setup + solve) relative to the smallest size: "
              + ", ".join(f"n = {n:,}: {v / base:.2f}x" for n, v in sorted(per_unknown.items()))
              + " (goal: within 1.3x)")


if __name__ == "__main__":
    main()
