"""3D Poisson benchmark: P1 tetrahedra, femkit against scikit-fem (assembly) and pyamg (solve).

Run by hand::

    python benchmarks/bench_poisson3d.py [--coarse 3] [--levels 5] [--repeat 3] [--no-solve]
                                         [--no-assembly] [--numbering rcm|none]
    python benchmarks/bench_poisson3d.py --memory [--coarse 3] [--levels 5] [--limit-gb 16]
    python benchmarks/bench_poisson3d.py --memory --sizes 1M 4M [--skip-peer] [--limit-gb 16]

The mesh is ``structured_box(c, c, c)`` refined ``levels`` times by Bey's red refinement (the
Kuhn box of ``c 2^levels`` cells per side; c = 3, levels = 5: 97^3 = 912,673 nodes, 5.3M
tetrahedra, the ~1M-unknown target; c = 5: 161^3 = 4.17M nodes, 24.6M tetrahedra), numbered as
``femkit solve`` numbers tetrahedral hierarchies (reverse Cuthill-McKee, midpoints next to their
edges; ``--numbering none``: the refinement's own). BLAS and numba threads are pinned to 1. Printed:

- assembly: ``skfem`` = ``Basis(MeshTet, ElementTetP1(), intorder=1)`` + ``asm(laplace)`` +
  ``asm(unit load)``; femkit's first call = ``assemble_stiffness`` + ``assemble_load`` on a new
  mesh object (CSR pattern built in the call; numba compile excluded: cached on disk), both by
  the one-off path (``keep_pattern=False``, what ``femkit solve`` does: rows from the node ->
  element incidences, then each element once, no slot map) and by the fused element-order pass
  that keeps the pattern; medians of interleaved runs, and the ratios;
- solve to the discretisation error of ``u = exp(x + y/2 - 3z/10)`` (Dirichlet data = u):
  ``fmg`` on the nested boxes given the Dirichlet values (as ``femkit solve`` calls it; its own
  stopping rule; the time includes its set-up: symmetry check, transfers, Galerkin products),
  then pyamg Ruge-Stueben and smoothed aggregation (set-up + ``solve(accel="cg")``) with the
  tolerance lowered by 10x until their L2 error is within 1 % of fmg's (counted: the set-up and
  the solve at that tolerance); wall times in seconds and in units of one SpMV ``A @ x`` (SciPy
  CSR), each row in the unit measured around it (fmg: medians around its runs; each pyamg
  solver: right before and after it), so a load that changes between rows moves the unit too;
- ``--memory``: peak RSS (``/usr/bin/time -v``) of ``python -m femkit.cli solve`` on the same cube
  case (kuhn_cube h = 1/c, ``refine: levels``, fmg, errors, no VTU/PNG) and of the peer job on
  the identical mesh read from ``.npz`` (scikit-fem ``MeshTet`` + ``ElementTetP1`` assembly,
  ``condense``, pyamg smoothed aggregation CG to 1e-6, the L2 error), each a fresh process;
  ``--limit-gb`` caps each one's address space (``ulimit -v``) so a peer that cannot fit fails
  instead of taking the machine; ``--sizes 117k 1M 4M`` runs named sizes in turn,
  ``--skip-peer`` the femkit row alone. Printed: wall, peak RSS, exit code, the L2 error and
  ``femkit solve``'s stage times, and the femkit / peer peak ratio.
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402


def exact(x, y, z):
    return np.exp(x + 0.5 * y - 0.3 * z)


def source(x, y, z):
    return -(1.0 + 0.25 + 0.09) * exact(x, y, z)


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def assembly(mesh, repeat: int) -> None:
    import skfem
    from skfem.helpers import dot, grad

    from femkit.fem import _kernels, _one_off_stiffness, assemble_load, assemble_stiffness
    from femkit.mesh import Mesh

    _kernels.warm_up()
    _one_off_stiffness.warm_up()
    laplace = skfem.BilinearForm(lambda u, v, w: dot(grad(u), grad(v)))
    unit = skfem.LinearForm(lambda v, w: 1.0 * v)

    def skfem_run():
        basis = skfem.Basis(skfem.MeshTet(mesh.points.T.copy(), mesh.cells.T.copy()),
                            skfem.ElementTetP1(), intorder=1)
        return laplace.assemble(basis), unit.assemble(basis)

    def femkit_run(keep: bool):
        fresh = Mesh(mesh.points, mesh.cells)           # no cached pattern
        return assemble_stiffness(fresh, keep_pattern=keep), assemble_load(fresh, 1.0)

    sk, rows, fused = [], [], []
    for r in range(repeat):
        sk.append(timed(skfem_run)[0])
        for keep in ((False, True) if r % 2 == 0 else (True, False)):  # alternate who follows skfem
            t, (K, F) = timed(lambda: femkit_run(keep))
            (fused if keep else rows).append(t)
    Ks, Fs = skfem_run()
    err = abs(K - Ks).max() / abs(Ks).max()
    t_sk, t_rows, t_fused = (statistics.median(v) for v in (sk, rows, fused))
    print(f"assembly: skfem {t_sk:.2f} s; femkit first call, one-off path (as femkit solve) "
          f"{t_rows:.2f} s, ratio {t_sk / t_rows:.1f}x; fused pass keeping the pattern "
          f"{t_fused:.2f} s, ratio {t_sk / t_fused:.1f}x (max |K - K_skfem| / max |K| = "
          f"{err:.1e}, |F - F_skfem| = {abs(F - Fs).max():.1e})")


def spmv_time(A, repeat: int = 20) -> float:
    """Median wall time of one SciPy CSR product ``A @ x`` (the unit of the solve table)."""
    x = np.ones(A.shape[0])
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        A @ x
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def solve(H, repeat: int) -> None:
    import pyamg

    from femkit.fem import apply_dirichlet, assemble_load, assemble_stiffness, error_norms
    from femkit.mesh import boundary_nodes
    from femkit.solvers import solve as fk_solve

    mesh = H.finest
    nodes = boundary_nodes(mesh)
    sys_ = apply_dirichlet(assemble_stiffness(mesh), assemble_load(mesh, source), nodes,
                           exact(*mesh.points[nodes].T))
    A = sys_.A.tocsr()
    l2 = lambda x: error_norms(mesh, sys_.expand(x), exact)["L2"]  # noqa: E731
    # the Dirichlet data: fmg builds consistent coarse problems from it (no level assembly)
    g = sys_.expand(np.zeros(len(sys_.free)))
    run = lambda: fk_solve(A, sys_.b, method="fmg", hierarchy=H, free=sys_.free,  # noqa: E731
                           dirichlet=g)
    run()  # compiled kernels loaded from the cache, pages touched
    fmg_t, spmvs = [], []
    for _ in range(repeat):
        spmvs.append(spmv_time(A))
        t, res = timed(run)
        fmg_t.append(t)
    spmvs.append(spmv_time(A))
    spmv = statistics.median(spmvs)
    t_fmg = statistics.median(fmg_t)
    target = l2(res.x)
    info = res.info
    print(f"solve: n = {A.shape[0]} free unknowns, nnz {A.nnz} ({A.nnz / A.shape[0]:.1f} per row), "
          f"SpMV {spmv * 1e3:.2f} ms (median of {len(spmvs)} x 20)")
    print(f"fmg: V({info['sweeps']},{info['sweeps']}) cycles per level {info['cycles_per_level']}, "
          f"operator complexity {info['operator_complexity']:.3f}, stopped by "
          f"{info['stopped_by']}; setup {res.setup_time / spmv:.0f} SpMV, cycles "
          f"{res.solve_time / spmv:.0f} SpMV (last run)")
    rows = [("femkit fmg", t_fmg, spmv, target, f"median of {repeat}")]
    for name, build in (("pyamg RS", pyamg.ruge_stuben_solver),
                        ("pyamg SA", pyamg.smoothed_aggregation_solver)):
        before = spmv_time(A)
        t_setup, ml = timed(lambda: build(A))
        for tol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9):
            t_solve, x = timed(lambda: ml.solve(sys_.b, tol=tol, accel="cg"))
            err = l2(x)
            if err <= 1.01 * target:
                break
        # its own unit, measured right before and after it (the load moves between the rows);
        # counted: the set-up and the one solve at the tolerance that reaches fmg's error
        unit = statistics.median([before, spmv_time(A)])
        rows.append((name, t_setup + t_solve, unit, err,
                     f"tol {tol:g}: setup {t_setup / unit:.0f} + solve {t_solve / unit:.0f} SpMV "
                     f"(SpMV {unit * 1e3:.2f} ms around it)"))
    print(f"{'solver':12s} {'seconds':>8s} {'SpMV units':>10s} {'L2 error':>10s}")
    for name, t, unit, err, note in rows:
        print(f"{name:12s} {t:8.2f} {t / unit:10.0f} {err:10.3e} {note}")
    best = min(t / unit for _, t, unit, _, _ in rows[1:])
    print(f"fmg / best pyamg in SpMV units: {t_fmg / spmv / best:.3f} (goal <= 0.2)")


CASE = """problem: poisson
name: bench3d
mesh: {{geometry: kuhn_cube, h: {h}, refine: {k}}}
source: "-(1 + 0.25 + 0.09) * exp(x + 0.5*y - 0.3*z)"
boundary:
  dirichlet: [{{tags: [boundary], value: "exp(x + 0.5*y - 0.3*z)"}}]
exact:
  u: "exp(x + 0.5*y - 0.3*z)"
  grad: ["exp(x + 0.5*y - 0.3*z)", "0.5*exp(x + 0.5*y - 0.3*z)", "-0.3*exp(x + 0.5*y - 0.3*z)"]
solver: {{method: fmg}}
output: {{vtu: false, plot: false}}
"""

PEER = """
import numpy as np, pyamg, skfem
from skfem.helpers import dot, grad
d = np.load({mesh!r})
m = skfem.MeshTet(d["points"].T.copy(), d["cells"].T.copy())
del d
basis = skfem.Basis(m, skfem.ElementTetP1(), intorder=1)
u = lambda x, y, z: np.exp(x + 0.5 * y - 0.3 * z)
A = skfem.BilinearForm(lambda u, v, w: dot(grad(u), grad(v))).assemble(basis)
b = skfem.LinearForm(lambda v, w: -1.34 * u(*w.x) * v).assemble(basis)
D = basis.get_dofs().all()
g = basis.zeros()
g[D] = u(*m.p[:, D])
Ai, bi, xi, I = skfem.condense(A, b, x=g, D=D)
x = pyamg.smoothed_aggregation_solver(Ai).solve(bi, tol=1e-6, accel="cg")
g[I] = x
err = skfem.Functional(lambda w: (w["uh"] - u(*w.x)) ** 2).assemble(
    skfem.Basis(m, skfem.ElementTetP1(), intorder=4), uh=g)
print("L2", np.sqrt(err))
"""


def peak_rss(cmd: list[str], limit_gb: float | None) -> tuple[float, float, int, str]:
    """Wall seconds, peak RSS (GB, ``/usr/bin/time -v``), exit code and the output's last line
    of ``cmd`` in a fresh process (``ulimit -v`` when ``limit_gb`` is given)."""
    import shlex
    import subprocess

    line = "/usr/bin/time -v " + " ".join(shlex.quote(c) for c in cmd)
    if limit_gb:
        line = f"ulimit -v {int(limit_gb * 2**20)}; {line}"
    t0 = time.perf_counter()
    out = subprocess.run(["bash", "-c", line], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    rss = [ln for ln in out.stderr.splitlines() if "Maximum resident set size" in ln]
    gb = int(rss[0].split()[-1]) / 2**20 if rss else float("nan")
    text = (out.stdout.strip().splitlines() or [""])[-1]
    if out.returncode:  # the process's last stderr line before /usr/bin/time's report
        err = out.stderr.strip().splitlines()
        cut = next((i for i, ln in enumerate(err) if "Command being timed" in ln), len(err))
        err = [ln for ln in err[:cut] if not ln.startswith("Command exited")]
        text = (err or [""])[-1][:160]
    return wall, gb, out.returncode, text


#: ``--sizes`` names: (coarse cells per side, red refinements) of the Kuhn cube.
SIZES = {"117k": (3, 4), "1M": (3, 5), "4M": (5, 5)}


def memory(coarse: int, levels: int, limit_gb: float | None, skip_peer: bool = False,
           force: bool = False) -> None:
    """Peak memory of ``femkit solve`` on the cube case against scikit-fem + pyamg on its mesh."""
    import json
    import sys
    import tempfile
    from pathlib import Path

    from femkit.mesh import MeshHierarchy, generate

    tmp = Path(tempfile.mkdtemp(prefix="bench3d-"))
    case = tmp / "cube.yaml"
    case.write_text(CASE.format(h=repr(1.0 / coarse), k=levels))
    n = coarse * 2 ** levels + 1
    print(f"memory: kuhn_cube h = 1/{coarse} refined {levels} times: {n ** 3} nodes, "
          f"{6 * (n - 1) ** 3} tetrahedra")
    env_py = sys.executable
    rows = [("femkit solve", [env_py, "-m", "femkit.cli", "solve", str(case), "-o", str(tmp / "out")]
             + (["--force"] if force else []))]
    if not skip_peer:  # the same mesh, written for the peer (untimed)
        fine = MeshHierarchy.from_refinement(generate("kuhn_cube", 1.0 / coarse), levels,
                                             renumber="rcm").finest
        np.savez(tmp / "mesh.npz", points=fine.points, cells=fine.cells)
        del fine
        rows.append(("skfem + pyamg SA", [env_py, "-c", PEER.format(mesh=str(tmp / "mesh.npz"))]))
    peaks = {}
    for name, cmd in rows:
        wall, gb, rc, text = peak_rss(cmd, limit_gb)
        result = tmp / "out" / "result.json"
        if name.startswith("femkit") and result.exists():
            res = json.loads(result.read_text())
            stages = ", ".join(f"{k} {v:.1f}" for k, v in res["timings"].items())
            text = f"L2 {res['errors']['L2']!r}; stages (s): {stages}"
        print(f"{name:18s} {wall:7.1f} s  peak RSS {gb:6.2f} GB  exit {rc}  {text}")
        if rc == 0:
            peaks[name] = gb
    if len(peaks) == 2:
        print(f"femkit / peer peak RSS: {peaks['femkit solve'] / peaks['skfem + pyamg SA']:.2f} "
              "(goal: below 1)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--coarse", type=int, default=3)
    ap.add_argument("--levels", type=int, default=5)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-solve", action="store_true", help="assembly only")
    ap.add_argument("--no-assembly", action="store_true", help="solve only")
    ap.add_argument("--memory", action="store_true",
                    help="only the peak memory of femkit solve against scikit-fem + pyamg")
    ap.add_argument("--limit-gb", type=float, default=None,
                    help="address-space limit of each --memory process (ulimit -v)")
    ap.add_argument("--sizes", nargs="+", choices=tuple(SIZES), default=None,
                    help="--memory at these named sizes (overrides --coarse/--levels): "
                         + ", ".join(f"{k} = h 1/{c} refined {k_}" for k, (c, k_) in SIZES.items()))
    ap.add_argument("--force", action="store_true",
                    help="--memory: pass --force to femkit solve (its memory guard's model "
                         "prices a 4M-node cube far above what it takes)")
    ap.add_argument("--skip-peer", action="store_true",
                    help="--memory: femkit solve only (a peer that cannot fit is not started)")
    ap.add_argument("--numbering", choices=("rcm", "none"), default="rcm",
                    help="rcm (default): as femkit solve numbers tetrahedral hierarchies; "
                         "none: the refinement's own (coarse nodes first)")
    args = ap.parse_args()
    if args.memory:
        for coarse, levels in ([SIZES[k] for k in args.sizes] if args.sizes
                               else [(args.coarse, args.levels)]):
            memory(coarse, levels, args.limit_gb, args.skip_peer, args.force)
        return
    from femkit.mesh import MeshHierarchy, structured_box

    t, H = timed(lambda: MeshHierarchy.from_refinement(
        structured_box(args.coarse, args.coarse, args.coarse), args.levels,
        renumber=args.numbering))
    m = H.finest
    print(f"mesh: {m.n_points} nodes, {m.n_cells} tetrahedra, numbering {args.numbering} "
          f"(hierarchy {t:.2f} s)")
    if not args.no_assembly:
        assembly(m, args.repeat)
    if not args.no_solve:
        solve(H, args.repeat)


if __name__ == "__main__":
    main()
