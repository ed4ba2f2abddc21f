"""Dynamics benchmark (run by hand): ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_dynamics.py [--quick] [--matrix-free]``.

Scenes
------
* Liu et al.'s cloth (81 x 81 nodes, 38,558 springs), fast mass-spring with 10 local/global
  iterations per 1/30 s frame (paper: 50 ms/frame in C++; REFERENCE.md: scipy ``splu`` on the
  shared ``n x n`` matrix with 3 right-hand sides, 47-67 ms/frame), and one Baraff-Witkin step
  on the same cloth (one sparse factorisation of 19,677 unknowns; REFERENCE.md: one Newton step
  of implicit Euler there, sparse LU, 0.55-0.7 s).
* A 128 x 128 cloth (97,026 springs, ``k = 3e4``, the Taichi demo's ``spring_Y``) with the
  per-node mass chosen so that ``dt omega_max = 1.6`` at the demo's ``dt = 3.125e-4`` (the
  demo's regime, REFERENCE.md): symplectic Euler (Taichi CPU: 424-525 substeps/s), and
  Baraff-Witkin and Newton implicit Euler at ``dt = 1/60`` (direct solver; the fill-reducing
  ordering is computed once and reused by every factorisation).

Baraff-Witkin runs with ``fix="clamp"`` (as Newton does by default): without it, compressed
springs make ``M + h^2 K`` indefinite on the hanging cloth (negative diagonal entries on Liu's
cloth after one step), the symmetric-mode factorisation no longer applies and SuperLU falls
back to partial pivoting (1.6x the fill, ~2x the time).

Every figure is the median over repeats after one warm-up step (which pays one-time setup:
the fast mass-spring factorisation, the implicit methods' ordering). The table prints the time
per step, factorisations per step, the time split of the implicit methods (assembly =
everything outside the permutation, the factorisation, the triangular solves and the PCG solves
preconditioned with a reused factor) and the reference figure with the ratio ours / reference.
Baraff-Witkin (BW) and Newton run twice: ``exact`` (a factorisation per linear solve) and
``reuse`` (an older factorisation preconditions PCG to the same tolerance ``rtol = 1e-10``,
refactorised when PCG is slow).

Matrix-free (Baraff and Witkin 1998 solve their step by CG, which needs only products):
Baraff-Witkin (clamp) on the 128 x 128 cloth at ``dt = 1/60`` three ways, all to
``rtol = 1e-10``: assembled + direct, assembled + PCG (Jacobi), and ``matrix_free=True`` + PCG (Jacobi, diagonal from the spring blocks): time per step, PCG
iterations per step and the memory of the assembled free-dof matrix (``nnz * 12`` bytes of
values and column indices + ``indptr``; the matrix-free path stores none).

Compiled (``--compiled``, issue 11): each implicit step three ways in the same run, SuperLU with
the NumPy spring passes (the baseline), ``cholesky`` (CHOLMOD) and ``cholesky`` with
``options: {engine: pardiso}`` (MKL PARDISO, when the extra ``femkit[pardiso]`` is installed),
plus symplectic Euler against Taichi's own demo. ``--engines``: the numeric refactorisation
alone per engine and ordering on the Baraff-Witkin matrices (:func:`engine_rows`).

The whole command (``--liu [ENGINE]``, issue 19): the bundled ``cases/scenes/liu_cloth.yaml`` on
``cholesky`` (engine ``cholmod`` by default, or ``cholespy``) with its default outputs (a frame
every 2 steps, energy.csv, result.json), run as a user runs it (``femkit solve``, a fresh
process each), against the kernel's frame time on the identical system (built from the same
file) measured in this process, in the same run (:func:`liu_rows`).
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
from femkit.solvers import SolverSpec
from femkit.dynamics.topology import cloth_grid  # noqa: E402

_SPLIT = ("time_permute", "time_factorization", "time_solve", "time_pcg")


def _time_steps(system, name, dt, repeats, *, solver="direct", preconditioner="none",
                solver_options=None, **opts) -> dict:
    """Median seconds per step after a warm-up, factorisations and the time split per step."""
    ctx = StepContext(SolverSpec(solver, preconditioner, options=dict(solver_options or {})))
    integ = get_integrator(name, **opts)
    s = integ.start(system, system.x0, system.v0, 0.0, dt, ctx)
    s = integ.step(system, s, dt, ctx)  # warm-up: one-time factorisation / ordering
    before = dict(ctx.stats)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        s = integ.step(system, s, dt, ctx)
        times.append(time.perf_counter() - t0)
    per = {key: (ctx.stats.get(key, 0) - before.get(key, 0)) / repeats
           for key in ("factorizations", "linear_iterations", "symbolic_reuses") + _SPLIT}
    total = sum(times) / repeats
    split = {k: per[k] for k in _SPLIT}
    split["assembly"] = total - sum(split.values())
    iters = ctx.stats.get("newton_iterations", [])[1:]
    return {"median": statistics.median(times), "min": min(times),
            "factorizations": per["factorizations"],
            "pcg": per["linear_iterations"],
            "split": split, "total": total, "newton": iters, "x": s.x,
            "rho": ctx.stats.get("chebyshev_rho"), "symbolic_reuses": per["symbolic_reuses"]}


def _ref(ours: float, lo: float, hi: float) -> str:
    return f"{ours / hi:.2f}-{ours / lo:.2f}x"


def _fmt_time(sec: float) -> str:
    return f"{1e3 * sec:8.1f} ms" if sec < 10 else f"{sec:8.2f} s "


def _table_head(preamble: str, head: str) -> None:
    print(f"OPENBLAS_NUM_THREADS={os.environ['OPENBLAS_NUM_THREADS']}; medians after a warm-up "
          f"step; {preamble}")
    print(head)
    print("-" * len(head))


def _big_mass(dt_explicit: float = 3.125e-4) -> float:
    """Per-node mass of the 128 x 128 cloth with ``dt omega_max = 1.6`` at ``dt_explicit``."""
    unit = cloth_grid(128, 128, 1.0, 1.0, k_structural=3e4, k_shear=3e4, k_bending=3e4,
                      mass=1.0, pinned="top_corners", forces=[Gravity(9.81)])
    return (unit.omega_max() * dt_explicit / 1.6) ** 2  # omega scales as 1/sqrt(m)


def main(quick: bool = False) -> None:
    rows = []
    liu = cloth_grid(81, 81, 1.0, 1.0, k_structural=1e3, k_shear=1e3, k_bending=1e2,
                     total_mass=1.0, pinned="top_corners", forces=[Gravity(9.81)])
    r = _time_steps(liu, "fast_mass_spring", 1.0 / 30.0, 5 if quick else 20, iterations=10)
    rows.append(("Liu 81x81", "fast_mass_spring 10 it", "1/30", r,
                 "47-67 ms (scipy), 50 ms (paper, C++)", _ref(r["median"], 0.047, 0.067)))
    for reuse in (False, True):
        reps = (3 if quick else 8) * (3 if reuse else 1)
        r = _time_steps(liu, "implicit_euler", 1.0 / 30.0, reps, fix="clamp",
                        reuse_factorization=reuse)
        rows.append(("Liu 81x81", "BW clamp " + ("reuse" if reuse else "exact"), "1/30", r,
                     "0.55-0.7 s (1 Newton step, LU)", _ref(r["median"], 0.55, 0.7)))

    dt_explicit = 3.125e-4
    mass = _big_mass(dt_explicit)
    big = cloth_grid(128, 128, 1.0, 1.0, k_structural=3e4, k_shear=3e4, k_bending=3e4,
                     mass=mass, pinned="top_corners", forces=[Gravity(9.81)])
    r = _time_steps(big, "symplectic_euler", dt_explicit, 50 if quick else 300)
    rows.append(("cloth 128x128", "symplectic_euler", "3.125e-4", r,
                 "424-525 substeps/s (Taichi CPU)", _ref(r["median"], 1 / 525, 1 / 424)))
    for name, reps, opts in (("implicit_euler", 2 if quick else 4, {"fix": "clamp",
                                                                    "reuse_factorization": False}),
                             ("implicit_euler", 6 if quick else 12, {"fix": "clamp", "reuse_factorization": True}),
                             ("newton", 2 if quick else 4, {"max_iterations": 20,
                                                            "reuse_factorization": False}),
                             ("newton", 3 if quick else 8, {"max_iterations": 20, "reuse_factorization": True})):
        r = _time_steps(big, name, 1.0 / 60.0, reps, **opts)
        label = "BW clamp" if name == "implicit_euler" else name
        label += " reuse" if opts.get("reuse_factorization") else " exact"
        rows.append(("cloth 128x128", label,
                     "1/60", r, "-", "-"))

    _table_head(f"128x128 cloth: {big.n_springs} springs, {big.ndof} dofs, node mass {mass:.3g} "
                f"(dt omega_max = 1.6 at dt = {dt_explicit})",
                f"{'scene':14s} {'method':24s} {'dt':>8s} {'time/step':>11s} {'fact/step':>9s}  "
                f"{'split ms: assembly/permute/factor/solve/pcg':44s} {'reference':38s} ours/ref")
    for scene, method, dt, r, ref, ratio in rows:
        sp = r["split"]
        split = "-"
        if (r["factorizations"] or r["pcg"]) and method != "fast_mass_spring 10 it":
            split = (f"{1e3 * sp['assembly']:.0f} / {1e3 * sp['time_permute']:.0f} / "
                     f"{1e3 * sp['time_factorization']:.0f} / {1e3 * sp['time_solve']:.0f} / "
                     f"{1e3 * sp['time_pcg']:.0f}")
            if r["pcg"]:
                split += f" ({r['pcg']:.0f} pcg it)"
        if r["newton"]:
            method = f"{method} ({statistics.mean(r['newton']):.1f} it)"
        print(f"{scene:14s} {method:24s} {dt:>8s} {_fmt_time(r['median']):>11s} "
              f"{r['factorizations']:9.1f}  {split:44s} {ref:38s} {ratio}")
    matrix_free_rows(big, quick)


def matrix_free_rows(system, quick: bool = False) -> None:
    """Baraff-Witkin (clamp, dt = 1/60): assembled direct / assembled PCG-Jacobi / matrix-free
    PCG-Jacobi; time per step, PCG iterations per step, assembled-matrix memory."""
    from femkit.solvers.operators import restrict

    h = 1.0 / 60.0
    reps = 2 if quick else 4
    results = {}
    for label, solver, pc, mf in (("assembled + direct", "direct", "none", False),
                                  ("assembled + pcg (jacobi)", "pcg", "jacobi", False),
                                  ("matrix-free + pcg (jacobi)", "pcg", "jacobi", True)):
        results[label] = (solver, mf, _time_steps(system, "implicit_euler", h, reps, solver=solver,
                                                  preconditioner=pc, fix="clamp", matrix_free=mf))
    # the matrix of the last step (the planar start has exact zeros that later fill in)
    x = results["assembled + direct"][2]["x"]
    A = restrict(system.mass_matrix() + h * h * system.stiffness_matrix(x, fix="clamp"),
                 system.free_dofs)
    mem = A.nnz * 12 + A.indptr.nbytes
    print(f"\nMatrix-free Baraff-Witkin (clamp), cloth 128x128, dt = 1/60, rtol = 1e-10; "
          f"assembled free-dof matrix: n = {A.shape[0]}, nnz = {A.nnz}, {mem / 2**20:.1f} MiB")
    head = f"{'variant':34s} {'time/step':>11s} {'pcg it/step':>11s} {'matrix memory':>14s}"
    print(head)
    print("-" * len(head))
    for label, (solver, mf, r) in results.items():
        memory = "none" if mf else f"{mem / 2**20:.1f} MiB"
        it = f"{r['pcg']:.0f}" if solver != "direct" else "-"
        print(f"{label:34s} {_fmt_time(r['median']):>11s} {it:>11s} {memory:>14s}")


# ----------------------------------------------------------------------------- issue 11
TAICHI_N = 128


def taichi_substep_time(repeats: int) -> float | None:
    """Median seconds of one substep of Taichi's own cloth demo (``mass_spring_3d_ggui``:
    128 x 128 nodes, 12 neighbours per node, ``spring_Y = 3e4``, dashpot ``1e4``, drag, ball
    collision, symplectic Euler, ``dt = 4e-2 / n``) on Taichi's CPU backend with one thread and
    float64; ``None`` when taichi is not installed (it is not a femkit dependency)."""
    try:
        import taichi as ti
    except ImportError:
        return None
    ti.init(arch=ti.cpu, cpu_max_num_threads=1, default_fp=ti.f64, log_level=ti.WARN)
    n = TAICHI_N
    quad_size = 1.0 / n
    dt = 4e-2 / n
    gravity = ti.Vector([0, -9.8, 0])
    spring_Y, dashpot_damping, drag_damping = 3e4, 1e4, 1.0
    ball_radius = 0.3
    ball_center = ti.Vector.field(3, dtype=float, shape=(1,))
    ball_center[0] = [0, 0, 0]
    x = ti.Vector.field(3, dtype=float, shape=(n, n))
    v = ti.Vector.field(3, dtype=float, shape=(n, n))
    spring_offsets = [ti.Vector([i, j]) for i in range(-2, 3) for j in range(-2, 3)
                      if (i, j) != (0, 0) and abs(i) + abs(j) <= 2]

    @ti.kernel
    def initialize():
        for i, j in x:
            x[i, j] = [i * quad_size - 0.5, 0.6, j * quad_size - 0.5]
            v[i, j] = [0, 0, 0]

    @ti.kernel
    def substep():
        for i in ti.grouped(x):
            v[i] += gravity * dt
        for i in ti.grouped(x):
            force = ti.Vector([0.0, 0.0, 0.0])
            for spring_offset in ti.static(spring_offsets):
                j = i + spring_offset
                if 0 <= j[0] < n and 0 <= j[1] < n:
                    x_ij = x[i] - x[j]
                    v_ij = v[i] - v[j]
                    d = x_ij.normalized()
                    current_dist = x_ij.norm()
                    original_dist = quad_size * float(i - j).norm()
                    force += -spring_Y * d * (current_dist / original_dist - 1)
                    force += -v_ij.dot(d) * d * dashpot_damping * quad_size
            v[i] += force * dt
        for i in ti.grouped(x):
            v[i] *= ti.exp(-drag_damping * dt)
            offset_to_center = x[i] - ball_center[0]
            if offset_to_center.norm() <= ball_radius:
                normal = offset_to_center.normalized()
                v[i] -= min(v[i].dot(normal), 0) * normal
            x[i] += dt * v[i]

    initialize()
    substep()
    ti.sync()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        substep()
        ti.sync()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def compile_times() -> dict:
    """First-call compile time of the spring kernels (empty numba cache, a fresh process) and
    the load time from the on-disk cache (a second fresh process), in seconds."""
    import subprocess
    import tempfile

    code = ("import time; t0 = time.perf_counter(); import numpy as np;"
            "from femkit.dynamics.topology import cloth_grid;"
            "from femkit.dynamics.integrators import StepContext, get_integrator;"
            "from femkit.solvers import SolverSpec;"
            "s = cloth_grid(8, 8, 1.0, 1.0, k_structural=1e3, k_shear=1e3, k_bending=1e2,"
            " total_mass=1.0, pinned='top_corners');"
            "t1 = time.perf_counter();"
            "[get_integrator(m).step(s, get_integrator(m).start(s, s.x0, s.v0, 0.0, 0.01,"
            " StepContext(SolverSpec('cholesky'))), 0.01, StepContext(SolverSpec('cholesky')))"
            " for m in ('fast_mass_spring', 'implicit_euler', 'newton')];"
            "import femkit.dynamics.kernels.spring_kernels as k;"
            "k.spring_forces(s.x0, s._i, s._j, s.k, s.rest, 1e-12, np.zeros_like(s.x0));"
            "print(time.perf_counter() - t1)")
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=tmp)
        for label in ("cold", "cached"):
            r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                               text=True, check=True)
            out[label] = float(r.stdout.strip().splitlines()[-1])
    return out


#: The linear solvers compared: the baseline (SuperLU + NumPy passes) and the compiled path with
#: either Cholesky engine (CHOLMOD; MKL PARDISO when installed).
VARIANTS = {"direct": ("direct", {}), "cholesky": ("cholesky", {}),
            "pardiso": ("cholesky", {"engine": "pardiso"})}


def _variants():
    from femkit.solvers.pardiso import available

    return [v for v in VARIANTS if v != "pardiso" or available()]


def _timed_variants(system, name, dt, reps, **opts) -> dict:
    return {v: _time_steps(system, name, dt, reps, solver=VARIANTS[v][0],
                           solver_options=VARIANTS[v][1], **opts) for v in _variants()}


def compiled_rows(quick: bool = False) -> None:
    """Issue 11: the compiled/Cholesky path (CHOLMOD, and MKL PARDISO when installed) against
    the SuperLU/NumPy path of the same step, measured in this run, and symplectic Euler against
    Taichi's demo."""
    rows = []
    liu = cloth_grid(81, 81, 1.0, 1.0, k_structural=1e3, k_shear=1e3, k_bending=1e2,
                     total_mass=1.0, pinned="top_corners", forces=[Gravity(9.81)])
    h = 1.0 / 30.0
    reps = 5 if quick else 20
    fms = _timed_variants(liu, "fast_mass_spring", h, reps, iterations=10)
    cheb = _time_steps(liu, "fast_mass_spring", h, reps, solver="cholesky", iterations=10,
                       chebyshev=True)
    rows.append(("Liu 81x81", "fast mass-spring, 10 it", fms, "<= 10 ms/frame"))
    rows.append(("Liu 81x81", "  + Chebyshev (Wang 2015)", {"cholesky": cheb}, ""))
    frame = min(fms[v]["median"] for v in fms if v != "direct")
    for label, name, opts in (("Newton iteration (1 solve)", "newton", {"max_iterations": 1}),
                              ("Newton iteration, reused factor", "newton",
                               {"max_iterations": 1, "reuse_factorization": True}),
                              ("Baraff-Witkin (clamp)", "implicit_euler", {"fix": "clamp"}),
                              ("Newton, converged (tol 1e-10)", "newton", {"max_iterations": 50}),
                              ("Newton, converged, reused factor", "newton",
                               {"max_iterations": 50, "reuse_factorization": True})):
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reps = (2 if quick else 5) * (3 if opts.get("reuse_factorization") else 1)
            r = _timed_variants(liu, name, h, reps, **opts)
        it = r["cholesky"]["newton"]
        extra = f" ({statistics.mean(it):.1f} it)" if it and opts.get("max_iterations", 1) > 1 else ""
        best = min(r[v]["median"] for v in r if v != "direct")
        rows.append(("Liu 81x81", label + extra, r, f"{best / frame:.1f} FMS frames (best engine)"))
    dt_explicit = 3.125e-4
    mass = _big_mass(dt_explicit)
    big = cloth_grid(128, 128, 1.0, 1.0, k_structural=3e4, k_shear=3e4, k_bending=3e4,
                     mass=mass, pinned="top_corners", forces=[Gravity(9.81)])
    bw = _timed_variants(big, "implicit_euler", 1.0 / 60.0, 2 if quick else 5, fix="clamp")
    rows.append(("cloth 128x128", "Baraff-Witkin (clamp), 1/60", bw, ">= 3x faster"))
    import femkit.dynamics.system as system_module

    limit = system_module.COMPILED_SPRINGS
    system_module.COMPILED_SPRINGS = 10 ** 12          # the NumPy sparse-product forces
    se_numpy = _time_steps(big, "symplectic_euler", dt_explicit, 50 if quick else 300)
    system_module.COMPILED_SPRINGS = limit
    se = _time_steps(big, "symplectic_euler", dt_explicit, 50 if quick else 300)
    taichi = taichi_substep_time(50 if quick else 300)
    ref = "taichi not installed" if taichi is None else f"Taichi 1.7.4 CPU: {1e3 * taichi:.2f} ms"
    rows.append(("cloth 128x128", "symplectic Euler", {"direct": se_numpy, "cholesky": se},
                 ref + ("" if taichi is None else f", ours {taichi / se['median']:.2f}x faster")))

    _table_head(f"baseline = SuperLU (direct) and the NumPy sparse-product spring passes, "
                f"measured in this run; 128x128 cloth: {big.n_springs} springs, node mass {mass:.3g}",
                f"{'scene':14s} {'method':38s} {'SuperLU/NumPy':>14s} {'CHOLMOD/compiled':>17s} "
                f"{'PARDISO/compiled':>17s} {'speed-up':>9s}  note")
    for scene, label, r, note in rows:
        cells = [_fmt_time(r[v]["median"]) if v in r else "-" for v in VARIANTS]
        ours = [r[v]["median"] for v in ("cholesky", "pardiso") if v in r]
        ratio = f"{r['direct']['median'] / min(ours):.2f}x" if "direct" in r else "-"
        print(f"{scene:14s} {label:38s} {cells[0]:>14s} {cells[1]:>17s} {cells[2]:>17s} "
              f"{ratio:>9s}  {note}")
    print("best (minimum) times, ms: " + "; ".join(
        f"{name} " + " / ".join(f"{1e3 * r[v]['min']:.1f}" for v in VARIANTS if v in r)
        for name, r in (("fast mass-spring", fms), ("Chebyshev", {"cholesky": cheb}),
                        ("BW 128x128", bw), ("symplectic Euler", {"cholesky": se}))))
    for v in bw:
        print(f"BW 128x128 {v}: factorisations/step {bw[v]['factorizations']:.1f}, "
              f"symbolic analyses reused/step {bw[v].get('symbolic_reuses', 0):.1f}; split ms: "
              + ", ".join(f"{k} {1e3 * t:.0f}" for k, t in bw[v]["split"].items()))
    print(f"\nChebyshev spectral radius estimated from the first step: {cheb['rho']:.4f}")
    ct = compile_times()
    print(f"numba kernels, first call in a fresh process: {ct['cold']:.2f} s with an empty cache "
          f"(compilation), {ct['cached']:.2f} s from the on-disk cache")


def engine_rows() -> None:
    """``--engines``: the numeric refactorisation alone, per Cholesky engine and ordering, on the
    Baraff-Witkin (clamp) matrices the benchmark's steps factorise (Liu's cloth after three steps
    at dt = 1/30, the 128 x 128 cloth after three steps at dt = 1/60): median of 5 refactorisations
    of the same matrix on its kept analysis, nnz(L) and flops (CHOLMOD's sum of squared column
    counts; PARDISO's row divides the CHOLMOD nested-dissection count by its time, a rate estimate:
    its own fill differs by ~10%)."""
    import numpy as np

    from femkit.solvers.operators import restrict
    from femkit.solvers import factorize_spd
    from femkit.solvers.pardiso import available

    scenes = {
        "Liu 81x81": (cloth_grid(81, 81, 1.0, 1.0, k_structural=1e3, k_shear=1e3, k_bending=1e2,
                                 total_mass=1.0, pinned="top_corners", forces=[Gravity(9.81)]), 1 / 30),
        "cloth 128x128": (cloth_grid(128, 128, 1.0, 1.0, k_structural=3e4, k_shear=3e4,
                                     k_bending=3e4, mass=_big_mass(), pinned="top_corners",
                                     forces=[Gravity(9.81)]), 1 / 60)}
    print(f"{'scene':14s} {'engine':8s} {'ordering':8s} {'numeric ms':>10s} {'nnz(L)':>10s} "
          f"{'Mflop':>7s} {'GFlop/s':>7s}")
    for label, (system, h) in scenes.items():
        ctx = StepContext(SolverSpec("cholesky"))
        integ = get_integrator("implicit_euler", fix="clamp")
        state = integ.start(system, system.x0, system.v0, 0.0, h, ctx)
        for _ in range(3):
            state = integ.step(system, state, h, ctx)
        A = restrict(system.mass_matrix() + h * h * system.stiffness_matrix(state.x, fix="clamp"),
                     system.free_dofs).tocsr()
        A.eliminate_zeros()  # the planar cloth's out-of-plane couplings, as the step leaves them out
        flops = {}
        for engine, ordering in (("cholmod", "amd"), ("cholmod", "nesdis"), ("pardiso", "nesdis")):
            if engine == "pardiso" and not available():
                continue
            F = factorize_spd(A, ordering=ordering, engine=engine)
            times = []
            for _ in range(5):
                t0 = time.perf_counter()
                F.refactor(A)
                times.append(time.perf_counter() - t0)
            t = statistics.median(times)
            if engine == "cholmod":
                cc = np.diff(F._f.copy().L().tocsc().indptr).astype(float)
                nnz_l, flops[ordering] = int(cc.sum()), float((cc * cc).sum())
            else:
                nnz_l = F.info["nnz_L"]
            fl = flops.get(ordering)
            print(f"{label:14s} {engine:8s} {ordering:8s} {1e3 * t:10.1f} {nnz_l:10d} "
                  f"{fl / 1e6 if fl else float('nan'):7.0f} {fl / t / 1e9 if fl else float('nan'):7.2f}")


LIU_CASE = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "cases", "scenes",
                        "liu_cloth.yaml")


def _cpu(who) -> float:
    import resource

    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


def _solve_scene(overrides: list[str], out: str) -> dict:
    """``femkit solve`` of the Liu scene in a fresh process: its result.json, the process's wall
    time (start to exit) and CPU time (user + system, all its threads)."""
    import json
    import resource
    import subprocess

    cmd = [sys.executable, "-m", "femkit.cli", "solve", LIU_CASE, "--quiet", "--output", out]
    for o in overrides:
        cmd += ["--set", o]
    c0, t0 = _cpu(resource.RUSAGE_CHILDREN), time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, _cpu(resource.RUSAGE_CHILDREN) - c0
    with open(os.path.join(out, "result.json")) as fh:
        res = json.load(fh)
    res.update(process_wall=wall, process_cpu=cpu)
    return res


def _kernel_frame(engine: str, repeats: int) -> tuple[float, float]:
    """The kernel: median wall seconds of one fast mass-spring frame on the scene's own system
    (after a warm-up frame, as :func:`_time_steps` measures), and its mean CPU seconds."""
    import resource

    from femkit.case import load_case
    from femkit.case.scene.run import build_system

    case = load_case(LIU_CASE, linear_solver__method="cholesky",
                     linear_solver__options={"engine": engine})
    system, _ = build_system(case)
    ctx = StepContext(SolverSpec("cholesky", options={"engine": engine}))
    integ = case.spec.integrator.build()
    h = case.spec.dt
    s = integ.step(system, integ.start(system, system.x0, system.v0, 0.0, h, ctx), h, ctx)
    times = []
    c0 = _cpu(resource.RUSAGE_SELF)
    for _ in range(repeats):
        t0 = time.perf_counter()
        s = integ.step(system, s, h, ctx)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), (_cpu(resource.RUSAGE_SELF) - c0) / repeats


def liu_rows(engine: str = "cholmod", rounds: int = 3) -> None:
    """Issue 19: the Liu scene through ``femkit solve`` against its kernel, in one run.

    Per round: the kernel's median frame (20 frames in this process), then ``femkit solve`` of
    the scene as bundled (60 steps, ``t_end = 2``) and of the same scene run three times as long
    (``t_end = 6``, 180 steps), each a fresh process with the default outputs. The marginal
    per-step wall of the whole command is the difference of the two processes' wall times (start
    to exit) over the 120 extra steps: everything a step costs (the step, energies and checks,
    the frame handed to the writer thread, waiting for it, the files) without the one-time costs
    (start-up, imports, factorisation, loading the compiled kernels), which are printed apart.
    The same difference of the processes' CPU time (all threads: the writer's work counted
    even when another core did it) is printed against the kernel's CPU time per frame: on a
    machine shared with other jobs the wall times swing by 2x from round to round, the CPU
    times by a few percent. Medians over ``rounds`` rounds; goal: marginal per-step wall <= 1.15
    x the kernel's frame."""
    import tempfile

    sets = ["linear_solver.method=cholesky", f"linear_solver.options={{engine: {engine}}}"]
    kernel, kcpu, marginal, mcpu, stage, whole, walls, frames = [], [], [], [], [], [], [], []
    last = {}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(rounds):
            kw, kc = _kernel_frame(engine, 20)
            kernel.append(kw)
            kcpu.append(kc)
            a = _solve_scene(sets, os.path.join(tmp, f"a{r}"))
            b = _solve_scene(sets + ["t_end=6"], os.path.join(tmp, f"b{r}"))
            extra = b["steps"] - a["steps"]
            marginal.append((b["process_wall"] - a["process_wall"]) / extra)
            mcpu.append((b["process_cpu"] - a["process_cpu"]) / extra)
            stage.append((b["timings"]["simulate"] - a["timings"]["simulate"]) / extra)
            whole.append(a["timings"]["simulate"] / a["steps"])
            walls.append(a["process_wall"])
            frames.append(a["frames"])
            last = a["timings"]
    k, m = statistics.median(kernel), statistics.median(marginal)
    kc, mc = statistics.median(kcpu), statistics.median(mcpu)

    def rounds_of(values):
        return ", ".join(f"{1e3 * t:.1f}" for t in values)

    print(f"Liu 81x81 cloth (cases/scenes/liu_cloth.yaml), fast_mass_spring 10 it, cholesky "
          f"(engine {engine}), default outputs ({frames[0]} frames of 60 steps); "
          f"OPENBLAS_NUM_THREADS={os.environ['OPENBLAS_NUM_THREADS']}; medians of {rounds} rounds; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{'':58s} {'wall ms':>8s} {'CPU ms':>8s}   rounds (wall)")
    print(f"{'kernel frame (bench_dynamics, in this process)':58s} {1e3 * k:8.1f} {1e3 * kc:8.1f}"
          f"   {rounds_of(kernel)}")
    print(f"{'femkit solve, marginal per step (processes, 180 - 60)':58s} {1e3 * m:8.1f} "
          f"{1e3 * mc:8.1f}   {rounds_of(marginal)}")
    print(f"{'femkit solve, marginal simulate stage per step':58s} "
          f"{1e3 * statistics.median(stage):8.1f}")
    print(f"{'femkit solve, simulate stage / steps (60, one-time incl.)':58s} "
          f"{1e3 * statistics.median(whole):8.1f}")
    print(f"femkit solve, 60 steps: process wall {statistics.median(walls):.2f} s; stages of the "
          "last: " + ", ".join(f"{n} {v:.3f} s" for n, v in last.items()))
    print(f"ratio femkit solve per step / kernel frame: wall {m / k:.3f}, CPU {mc / kc:.3f}  "
          "(goal <= 1.15)")

if __name__ == "__main__":
    if "--liu" in sys.argv:
        i = sys.argv.index("--liu")
        eng = sys.argv[i + 1] if len(sys.argv) > i + 1 and not sys.argv[i + 1].startswith("-") \
            else "cholmod"
        liu_rows(eng, rounds=1 if "--quick" in sys.argv else 3)
    elif "--engines" in sys.argv:
        engine_rows()
    elif "--compiled" in sys.argv:
        compiled_rows(quick="--quick" in sys.argv)
    elif "--matrix-free" in sys.argv:  # only the matrix-free comparison
        matrix_free_rows(cloth_grid(128, 128, 1.0, 1.0, k_structural=3e4, k_shear=3e4,
                                    k_bending=3e4, mass=_big_mass(), pinned="top_corners",
                                    forces=[Gravity(9.81)]), quick="--quick" in sys.argv)
    else:
        main(quick="--quick" in sys.argv)
