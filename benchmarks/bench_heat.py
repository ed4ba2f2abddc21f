"""Benchmark the heat kind: the cost of a step against its kept factor, and a whole
``femkit solve`` against the same job written with scikit-fem and SciPy.

Run by hand (not in CI)::

    python benchmarks/bench_heat.py                 # 0.47M unknowns per step, 0.24M whole solve
    python benchmarks/bench_heat.py --refine 2      # ~8x smaller, quick

1. **Per step.** ``u_t = lap u`` on the unit square (gmsh h = 0.0125, refined ``--refine`` times:
   0.47M nodes at 3), consistent mass, implicit Euler with a fixed ``dt``: the seconds per step of
   :func:`femkit.dynamics.mol.march` (one SpMV ``M_f u``, one pair of triangular solves of the kept
   factor of ``M + dt K``, the Dirichlet values; 20 steps after a first one that builds and
   factorises the matrix, reported apart) against one ``Factor.solve`` of that factor alone
   (median of 10). Goal (issue 33): at most 1.5x.
2. **Whole solve.** The same problem on a mesh file of ``--whole-refine`` refinements (0.24M nodes
   at h = 0.0175, refine 3), 100 implicit Euler steps, the error against ``exact`` at 11 frames,
   11 VTU frames and a PNG: ``femkit solve`` (a subprocess, wall time) against a script doing the
   same with scikit-fem's ``MeshTri``, ``Basis``, its ``mass`` and ``laplace`` forms, the
   Dirichlet nodes condensed, SciPy's ``splu`` of ``M + dt K`` (SuperLU with the symmetric ordering
   femkit uses, the peer's best settings: REFERENCE) reused for every step, scikit-fem's L2
   error, meshio's VTU writer and a matplotlib PNG. Goal (issue 33): at most 0.3x.

BLAS threads are pinned to 1. Both jobs run in the same invocation: compare their ratio.
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import textwrap  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DT, STEPS = 1e-4, 100


def per_step(refine: int, steps: int = 20) -> dict:
    """Seconds per implicit Euler step against one substitution pair of its kept factor."""
    from femkit.dynamics.mol import HEAT_INTEGRATORS, LinearSystem, get_scheme, march
    from femkit.fem import assemble_stiffness
    from femkit.fem.mass import mass_matrix
    from femkit.mesh import boundary_nodes, generate, refine as refine_mesh

    mesh = refine_mesh(generate("unit_square", 0.0125), refine)
    x, y = mesh.points.T
    u0 = np.sin(np.pi * x) * np.sin(np.pi * y)
    t0 = time.perf_counter()
    system = LinearSystem(mass_matrix(mesh), assemble_stiffness(mesh, 1.0), boundary_nodes(mesh, None))
    assembly = time.perf_counter() - t0
    scheme = get_scheme(HEAT_INTEGRATORS, "implicit_euler")
    first = march(system, scheme, u0, 0.0, DT, 1)  # builds and factorises the step's matrix
    setup = first.step_seconds
    run = march(system, scheme, first.frames[-1][1], DT, DT, steps)  # the kept factor only
    factor = system.operator(1.0, DT).factor
    b = system.M_f @ u0
    pairs = []
    for _ in range(10):
        t0 = time.perf_counter()
        factor.solve(b)
        pairs.append(time.perf_counter() - t0)
    pair = float(np.median(pairs))
    step = run.step_seconds / run.steps
    return {"unknowns": int(system.free.size), "assembly_s": assembly, "setup_s": setup,
            "factor_s": system.stats["factor_seconds"], "step_s": step, "pair_s": pair,
            "ratio": step / pair}


def solver_costs(method: str, mesh, steps: int = 10, dt: float = DT) -> dict:
    """Setup (the first step: matrix, factorisation or preconditioner) and seconds per later
    implicit Euler step of one linear solver on ``mesh`` (``u_t = lap u``, zero boundary)."""
    from femkit.dynamics.mol import HEAT_INTEGRATORS, LinearSystem, get_scheme, march
    from femkit.fem import assemble_stiffness
    from femkit.fem.mass import mass_matrix
    from femkit.mesh import boundary_nodes
    from femkit.solvers import SolverSpec

    pts = mesh.points
    u0 = np.prod(np.sin(np.pi * pts), axis=1)
    spec = SolverSpec.from_mapping(SOLVERS[method])
    system = LinearSystem(mass_matrix(mesh), assemble_stiffness(mesh, 1.0),
                          boundary_nodes(mesh, None), solver=spec)
    scheme = get_scheme(HEAT_INTEGRATORS, "implicit_euler")
    first = march(system, scheme, u0, 0.0, dt, 1)
    run = march(system, scheme, first.frames[-1][1], dt, dt, steps)
    st = system.stats
    return {"method": method, "unknowns": int(system.free.size), "setup_s": first.step_seconds,
            "step_s": run.seconds_per_step,
            "iterations": st.get("linear_iterations", 0) / max(1, st.get("linear_solves", 1)),
            "u": run.frames[-1][1]}


SOLVERS = {"direct": {"method": "direct"}, "cholesky": {"method": "cholesky"},
           "pcg+amg": {"method": "pcg", "preconditioner": "amg"},
           "pcg+amg_rs": {"method": "pcg", "preconditioner": "amg_rs"},
           "pcg+ic0": {"method": "pcg", "preconditioner": "ic0"}}


def grid(size: str):
    """``2d:N`` (N x N squares cut in triangles), ``3d:N`` (N^3 Kuhn cubes) or ``msh:H:K`` (the
    gmsh unit square of size H refined K times: an unstructured node numbering)."""
    from femkit.mesh import generate, refine as refine_mesh
    from femkit.mesh.structured import structured_box, structured_mesh

    kind, *arg = size.split(":")
    if kind == "msh":
        return refine_mesh(generate("unit_square", float(arg[0])), int(arg[1]))
    n = int(arg[0])
    return structured_mesh(n, n) if kind == "2d" else structured_box(n, n, n)


def compare_solvers(methods: list[str], sizes: list[str], dt: float = DT) -> None:
    """Print setup and per-step seconds of each solver on each :func:`grid` and the largest
    difference from the first solver's state."""
    for size in sizes:
        dim = size.split(":")[0]
        mesh = grid(size)
        ref = None
        for method in methods:
            r = solver_costs(method, mesh, dt=dt)
            diff = 0.0 if ref is None else float(np.abs(r["u"] - ref).max() / np.abs(ref).max())
            ref = r["u"] if ref is None else ref
            print(f"solvers    {dim} {r['unknowns']:,} unknowns {method:11s} setup {r['setup_s']:7.2f} s, "
                  f"step {r['step_s'] * 1e3:8.1f} ms ({r['iterations']:.1f} it/step), "
                  f"state vs {methods[0]} {diff:.1e}", flush=True)


def heat_3d(n: int, steps: int = 5, dt: float = DT) -> dict:
    """3D heat on ``n^3`` Kuhn cubes with the default rule's step solver
    (:func:`femkit.dynamics.mol.step_solver`: kept preconditioner, warm start): setup and
    seconds per step, against one stationary solve ``K u = f`` of the same mesh by the Poisson
    default (``pcg`` + smoothed-aggregation AMG, setup included) from zero."""
    from femkit.dynamics.mol import (HEAT_INTEGRATORS, LinearSystem, get_scheme, march,
                                     step_solver, stiffness_ratio)
    from femkit.fem import assemble_stiffness
    from femkit.fem.mass import mass_matrix
    from femkit.mesh import boundary_nodes
    from femkit.mesh.structured import structured_box
    from femkit.solvers import SolverSpec

    t0 = time.perf_counter()
    mesh = structured_box(n, n, n)
    M, K, fixed = mass_matrix(mesh), assemble_stiffness(mesh, 1.0), boundary_nodes(mesh, None)
    build = time.perf_counter() - t0
    free = np.setdiff1d(np.arange(mesh.n_points), fixed)
    spec = step_solver(3, free.size, None, stiffness_ratio(M, K, free, dt))
    system = LinearSystem(M, K, fixed, solver=spec)
    u0 = np.prod(np.sin(np.pi * mesh.points), axis=1)
    scheme = get_scheme(HEAT_INTEGRATORS, "implicit_euler")
    first = march(system, scheme, u0, 0.0, dt, 1)
    run = march(system, scheme, first.frames[-1][1], dt, dt, steps)
    st = dict(system.stats)
    K_ff = K[free][:, free].tocsr()
    b = M[free] @ np.ones(mesh.n_points)
    t0 = time.perf_counter()
    res = SolverSpec("pcg").solve(K_ff, b)
    stationary = time.perf_counter() - t0
    return {"unknowns": int(free.size), "solver": f"{spec.method}+{spec.preconditioner}",
            "build_s": build, "setup_s": first.step_seconds, "step_s": run.seconds_per_step,
            "iterations": st.get("linear_iterations", 0) / max(1, st.get("linear_solves", 1)),
            "stationary_s": stationary, "stationary_iterations": int(res.iterations),
            "ratio": run.seconds_per_step / stationary}


CASE = """\
problem: heat
name: bench_heat
mesh: {{file: {mesh}}}
initial: "sin(pi*x)*sin(pi*y)"
boundary:
  dirichlet:
    - {{tags: [boundary], value: 0}}
exact:
  u: "exp(-2*pi**2*t)*sin(pi*x)*sin(pi*y)"
integrator: implicit_euler
dt: {dt}
t_end: {t_end}
output: {{dir: out_femkit, frames: 10, vtu: true, png: true}}
"""

SKFEM = textwrap.dedent("""\
    import json, os, sys, time
    import numpy as np, meshio, skfem
    from scipy.sparse.linalg import splu
    from skfem.models.poisson import laplace, mass
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation
    path, out, dt, steps = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
    m = meshio.read(path)
    tri = np.vstack([c.data for c in m.cells if c.type == "triangle"])
    mesh = skfem.MeshTri(m.points[:, :2].T.copy(), tri.T.copy())
    basis = skfem.Basis(mesh, skfem.ElementTriP1())
    K, M = laplace.assemble(basis), mass.assemble(basis)
    D = mesh.boundary_nodes()
    I = np.setdiff1d(np.arange(mesh.p.shape[1]), D)
    A = (M + dt * K).tocsr()[I][:, I].tocsc()
    M_I = M.tocsr()[I][:, I].tocsr()
    lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=1e-3,
              options={"SymmetricMode": True})
    x, y = mesh.p
    u = np.sin(np.pi * x) * np.sin(np.pi * y)
    u[D] = 0.0
    @skfem.Functional
    def l2(w):
        ex = np.exp(-2 * np.pi ** 2 * w.t) * np.sin(np.pi * w.x[0]) * np.sin(np.pi * w.x[1])
        return (w.u - ex) ** 2
    os.makedirs(os.path.join(out, "frames"), exist_ok=True)
    errors, names = [], []
    def frame(k, t):
        errors.append(float(np.sqrt(l2.assemble(basis, u=basis.interpolate(u), t=t))))
        name = f"frames/frame_{k:05d}.vtu"
        meshio.write(os.path.join(out, name), meshio.Mesh(mesh.p.T, [("triangle", mesh.t.T)],
                                                          point_data={"u": u}))
        names.append((t, name))
    frame(0, 0.0)
    every = max(1, steps // 10)
    for k in range(1, steps + 1):
        u[I] = lu.solve(M_I @ u[I])
        if k % every == 0:
            frame(len(names), k * dt)
    with open(os.path.join(out, "heat.pvd"), "w") as f:
        f.write('<?xml version="1.0"?><VTKFile type="Collection"><Collection>')
        f.writelines(f'<DataSet timestep="{t}" file="{n}"/>' for t, n in names)
        f.write("</Collection></VTKFile>")
    fig = plt.figure(figsize=(6, 5), dpi=120)
    ax = fig.add_subplot()
    art = ax.tripcolor(Triangulation(x, y, mesh.t.T), u, shading="gouraud")
    fig.colorbar(art, ax=ax)
    fig.savefig(os.path.join(out, "final.png"))
    json.dump({"errors": errors, "max": max(errors)}, open(os.path.join(out, "result.json"), "w"))
""")


def whole_solve(refine: int) -> dict:
    """Wall seconds of ``femkit solve`` and of the scikit-fem + SciPy script, same mesh file."""
    from femkit.mesh import generate, refine as refine_mesh
    from femkit.mesh.io import write_mesh

    tmp = Path(tempfile.mkdtemp(prefix="bench_heat_"))
    mesh = refine_mesh(generate("unit_square", 0.0175), refine)
    path = tmp / "square.msh"
    write_mesh(path, mesh)
    (tmp / "heat.yaml").write_text(CASE.format(mesh=path, dt=DT, t_end=DT * STEPS))
    (tmp / "skfem_heat.py").write_text(SKFEM)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    out = {"unknowns": int(mesh.n_points)}
    for name, argv in (("femkit", [sys.executable, "-m", "femkit", "solve", "heat.yaml"]),
                       ("skfem", [sys.executable, "skfem_heat.py", str(path), "out_skfem",
                                  str(DT), str(STEPS)])):
        t0 = time.perf_counter()
        p = subprocess.run(argv, cwd=tmp, env=env, capture_output=True, text=True)
        out[f"{name}_s"] = time.perf_counter() - t0
        if p.returncode != 0:
            raise SystemExit(f"{name} failed:\n{p.stderr[-2000:]}")
    fk = json.loads((tmp / "out_femkit" / "result.json").read_text())
    sk = json.loads((tmp / "out_skfem" / "result.json").read_text())
    out["femkit_max_L2"] = fk["errors"]["max_over_time"]["L2"]
    out["skfem_max_L2"] = sk["max"]
    out["femkit_timings"] = fk["timings"]
    out["femkit_solver"] = fk["linear_solver"]
    out["ratio"] = out["femkit_s"] / out["skfem_s"]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--refine", type=int, default=3, help="per-step mesh: h 0.0125 refined k times")
    ap.add_argument("--whole-refine", type=int, default=3, help="whole solve: h 0.0175 refined k times")
    ap.add_argument("--skip-whole", action="store_true", help="the per-step measurement only")
    ap.add_argument("--skip-step", action="store_true", help="the whole solve only")
    ap.add_argument("--solvers", nargs="*", metavar="METHOD",
                    help=f"compare the step solvers ({', '.join(SOLVERS)}) instead")
    ap.add_argument("--sizes", nargs="*", default=["2d:245", "2d:500", "3d:58"],
                    help="with --solvers: 2d:N (N x N squares), 3d:N (N^3 Kuhn cubes), msh:H:K")
    ap.add_argument("--dt", type=float, default=DT, help="with --solvers: the step")
    ap.add_argument("--heat-3d", type=int, metavar="N",
                    help="3D heat on N^3 Kuhn cubes (N = 100: 1.03M nodes) against a stationary solve")
    args = ap.parse_args()
    if args.heat_3d:
        r = heat_3d(args.heat_3d, dt=args.dt)
        print(f"3d heat    {r['unknowns']:,} unknowns, {r['solver']} (kept, warm-started): step "
              f"{r['step_s']:.2f} s ({r['iterations']:.1f} it/step), first step {r['setup_s']:.2f} s; "
              f"one stationary solve (pcg+amg, setup included) {r['stationary_s']:.2f} s "
              f"({r['stationary_iterations']} it): ratio {r['ratio']:.3f}; mesh and matrices "
              f"{r['build_s']:.1f} s", flush=True)
        return
    if args.solvers is not None:
        compare_solvers(args.solvers or list(SOLVERS), args.sizes, args.dt)
        return
    a = None if args.skip_step else per_step(args.refine)
    if a:
        print(f"per step   {a['unknowns']:,} unknowns: implicit Euler step {a['step_s'] * 1e3:.1f} ms, "
              f"one substitution pair {a['pair_s'] * 1e3:.1f} ms: ratio {a['ratio']:.2f} (goal <= 1.5); "
              f"first step (matrix, factorisation) {a['setup_s']:.2f} s of which factorisation "
              f"{a['factor_s']:.2f} s, assembly {a['assembly_s']:.2f} s", flush=True)
    if args.skip_whole:
        return
    b = whole_solve(args.whole_refine)
    print(f"whole      {b['unknowns']:,} nodes, {STEPS} steps: femkit solve {b['femkit_s']:.2f} s, "
          f"scikit-fem + splu {b['skfem_s']:.2f} s: ratio {b['ratio']:.2f} (goal <= 0.3); "
          f"max L2 error femkit {b['femkit_max_L2']:.4e}, scikit-fem {b['skfem_max_L2']:.4e}")
    print("femkit stages: " + ", ".join(f"{k} {v:.2f} s" for k, v in b["femkit_timings"].items()))
    print("femkit linear solver: " + json.dumps(b["femkit_solver"]))


if __name__ == "__main__":
    main()
