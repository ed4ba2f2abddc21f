"""Fit the cost model's constants (femkit/cost/constants.json) from measured runs on this machine.

Every run is ``cost_probe.measure_poisson`` (beside this script) in a fresh process (BLAS on one thread):
per stage the wall time and the peak resident memory above the start (VmHWM reset per stage).
The fit follows the model in femkit/cost/poisson.py: per stage the peak memory is
``fixed + a * triangles`` with the fixed part the libraries loaded by then (gmsh, numba, pyamg,
matplotlib: measured here by importing them), ``a`` the median over the runs with at least
``--min-fit`` triangles; the seconds ``a m^p`` in log-log, for refine, quality, assembly and
boundary separately on the NumPy path (refined runs from 20,000 triangles up to
``COMPILED_FROM``) and the compiled one (the two largest refined sizes, median per size), where
numba's start-up (``numba_load``: import and registries, measured like the imports of pyamg
and matplotlib, fastest of three) is paid in the refine stage, the first to run compiled;
every run's seconds are brought to the fastest of the speed probes taken around the runs
(which becomes ``reference.speed_probe_seconds``) by its own probes, so that a shared machine's
load of the moment does not enter the constants; iteration
counts ``c n^p`` fitted in log-log over two sizes; gmsh's triangle count by least squares over
every bundled geometry.

    OPENBLAS_NUM_THREADS=1 python benchmarks/calibrate_cost.py              # print the constants
    OPENBLAS_NUM_THREADS=1 python benchmarks/calibrate_cost.py --write ~/.config/femkit/cost.json
    OPENBLAS_NUM_THREADS=1 python benchmarks/calibrate_cost.py --quick      # smaller runs (~1 min)
    OPENBLAS_NUM_THREADS=1 python benchmarks/calibrate_cost.py --tetrahedra [--levels 3 4 5]

``--tetrahedra`` fits the 3D memory laws (the ``tetrahedra`` section, femkit/cost/tetrahedra.py)
alone: ``cost_probe.measure_case`` runs ``femkit solve``'s pipeline on the Kuhn cube (h = 1/3,
refined 3, 4, 5 times: 83k to 5.3M tetrahedra; fmg, errors, estimate) in fresh processes; per
law the slope of the stage peak between the two largest runs, ``fixed_bytes`` the largest
intercept (total peak minus slope times tetrahedra) above the model's baseline. The margin is
not fitted: it is checked against whole-run peaks (docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from cost_probe import (CUBE_CASE, child_env, domain, measure_case_subprocess,  # noqa: E402
                        measure_poisson_subprocess)

from femkit.cost.constants import load_constants  # noqa: E402
from femkit.cost.poisson import COMPILED_FROM, COMPILED_STAGES, fixed_bytes, solver_key  # noqa: E402

#: Seconds constant each measured import sets (numba's: its start-up, paid in the first stage
#: that runs compiled).
IMPORT_SECONDS = {"numba_import": "numba_load", "pyamg_import": "pyamg_import",
                  "matplotlib_import": "png_fixed"}

#: Smallest runs the NumPy-path time laws (``<stage>_numpy``) are fitted on.
NUMPY_FIT_FROM = 20_000


#: What numba's start-up is: its import and the typing and lowering registries it loads before
#: its first compiled or cached function (``femkit.case.poisson.warmup.start_numba``).
NUMBA_START = ("import numba; from numba.core.registry import cpu_target; "
               "cpu_target.target_context.refresh()")


def _import_cost(module: str, repeat: int = 3) -> tuple[float, float, float]:
    """(bytes, seconds, speed probe) of importing ``module`` after femkit's baseline imports
    (fresh process; the fastest of ``repeat``, with the median speed probe just before it, by
    which the seconds are brought to the reference speed like the runs')."""
    from femkit.cost.speed import speed_probe

    stmt = NUMBA_START if module == "numba" else f"import {module}"
    code = ("import time, json; from cost_probe import preload; preload(); "
            "from femkit.cost.memory import current_rss; a = current_rss(); t = time.perf_counter(); "
            f"{stmt}; t = time.perf_counter() - t; print(json.dumps([current_rss() - a, t]))")
    got = []
    for _ in range(repeat):
        probe = speed_probe(statistic="median")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             check=True, env=child_env())
        got.append(json.loads(out.stdout.strip().splitlines()[-1]) + [probe])
    fastest = min(got, key=lambda g: g[1] / g[2])
    return float(np.median([g[0] for g in got])), float(fastest[1]), float(fastest[2])


def fit_triangle_count(hs=(0.04, 0.02, 0.01)) -> dict:
    """Least squares ``m = c_A A/h^2 + c_L L/h`` over the bundled geometries; boundary edges / (L/h)."""
    from femkit.mesh import GEOMETRIES, boundary_edges_topological, generate

    rows, rhs, bfrac = [], [], []
    for g in (name for name in GEOMETRIES.names() if GEOMETRIES.get(name).dim == 2):
        d = domain(g)
        area, length = d["area"], d["line_length"]
        for h in hs:
            mesh = generate(g, h)
            rows.append([area / h ** 2, length / h])
            rhs.append(mesh.n_triangles)
            if g == "unit_square":
                bfrac.append(len(boundary_edges_topological(mesh)) / (length / h))
    coef, *_ = np.linalg.lstsq(np.array(rows), np.array(rhs, float), rcond=None)
    pred = np.array(rows) @ coef
    worst = float(np.max(np.abs(pred / np.array(rhs) - 1)))
    print(f"triangle count: c_A {coef[0]:.4f}, c_L {coef[1]:.4f}; worst relative error {worst:.3f} "
          f"over {len(rhs)} meshes (h = {hs})")
    return {"triangles_per_area_h2": round(float(coef[0]), 4),
            "triangles_per_length_h": round(float(coef[1]), 4),
            "boundary_edges_per_length_h": round(float(np.median(bfrac)), 4)}


def power_law(sizes, seconds, lo: float = 0.8, hi: float = 1.5) -> dict:
    """Least-squares ``seconds = coefficient * size^exponent`` in log-log (exponent clipped)."""
    x, y = np.log(np.asarray(sizes, float)), np.log(np.maximum(np.asarray(seconds, float), 1e-6))
    p = float(np.clip(np.polyfit(x, y, 1)[0], lo, hi)) if len(set(sizes)) > 1 else 1.0
    a = float(np.exp(np.median(y - p * x)))
    return {"coefficient": a, "exponent": round(p, 3)}


def median_by_size(runs, stage) -> tuple[list, list]:
    """Triangle counts and the median of ``stage``'s seconds over the runs of each count."""
    by: dict[int, list] = {}
    for r in runs:
        if stage in r["stages"]:
            by.setdefault(r["n_triangles"], []).append(r["stages"][stage]["seconds"])
    sizes = sorted(by)
    return sizes, [float(np.median(by[m])) for m in sizes]


def _flags(run, c) -> dict:
    key = solver_key(run["method"], run["preconditioner"])
    return dict(gmsh=True, compiled=run["n_triangles"] >= COMPILED_FROM, generated=run["n_generated"],
                amg=key.startswith("pcg+amg"), png="png" in run["outputs"], constants=c,
                ic0=key == "pcg+ic0")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="smaller runs (largest 373k triangles)")
    ap.add_argument("--min-fit", type=float, default=80_000, help="fit per-triangle constants on runs this big")
    ap.add_argument("--write", help="write the fitted constants (complete JSON) to this file")
    ap.add_argument("--runs", help="also dump the raw measurements (JSON) to this file")
    ap.add_argument("--from-runs", help="fit from measurements dumped earlier with --runs (no runs)")
    ap.add_argument("--tetrahedra", action="store_true",
                    help="fit the 3D memory laws alone (the tetrahedra section)")
    ap.add_argument("--levels", type=int, nargs="+", default=[3, 4, 5],
                    help="--tetrahedra: refinements of the h = 1/3 Kuhn cube to measure")
    args = ap.parse_args(argv)

    c = load_constants()
    if args.tetrahedra:
        print(json.dumps({"tetrahedra": fit_tetrahedra(c, args.levels)}, indent=2))
        return 0
    if args.from_runs:
        with open(args.from_runs) as fh:
            saved = json.load(fh)
        c["mesh"].update(saved["mesh"])
        imports, runs = saved["imports"], saved["runs"]
    else:
        c["mesh"].update(fit_triangle_count())
        imports = {}
        for mod, key in (("numba", "numba_import"), ("pyamg", "pyamg_import"),
                         ("matplotlib.pyplot", "matplotlib_import")):
            imports[key] = _import_cost(mod)
            print(f"import {mod}: {imports[key][0] / 2**20:.1f} MiB, {imports[key][1]:.2f} s (speed probe {imports[key][2]:.4f} s)")
        runs = measure(args)
    probes = [r["speed_probe"] for r in runs if r.get("speed_probe")]
    measured = runs  # dumped as measured (--runs)
    if probes:  # each run's seconds brought to the fastest probe (the load of the moment out)
        ref = float(min(probes))
        runs = normalise_speed(runs, ref)
        print(f"speed probe around the runs: {min(probes):.4f}-{max(probes):.4f} s (median "
              f"{np.median(probes):.4f}); times brought to {ref:.4f}")
    else:  # runs dumped without probes: the probe now
        from femkit.cost.speed import speed_probe

        ref = speed_probe()
    for key, (nbytes, secs, *probe) in imports.items():
        c["bytes"][key] = round(nbytes, -5)
        if key in IMPORT_SECONDS:
            c["seconds"][IMPORT_SECONDS[key]] = round(secs * (ref / probe[0] if probe else 1.0), 3)
    fit(c, runs, args.min_fit)
    c["reference"]["speed_probe_seconds"] = round(ref, 4)

    def rnd(d):
        return {k: (rnd(v) if isinstance(v, dict) else (float(f"{v:.4g}") if isinstance(v, float) else v))
                for k, v in d.items()}

    c = rnd(c)
    text = json.dumps(c, indent=2)
    print(text)
    if args.write:
        with open(os.path.expanduser(args.write), "w") as fh:
            fh.write(text + "\n")
        print(f"written to {args.write}")
    if args.runs:
        with open(args.runs, "w") as fh:
            json.dump({"mesh": c["mesh"], "imports": imports, "runs": measured}, fh, indent=1)
    return 0


def measure(args) -> list[dict]:
    """The calibration runs (each in a fresh process)."""
    top = 3 if args.quick else 4
    runs = []

    from femkit.cost.speed import speed_probe

    def run(**kw):
        before = speed_probe(statistic="median")
        r = measure_poisson_subprocess(**kw)
        r["speed_probe"] = (before * speed_probe(statistic="median")) ** 0.5
        runs.append(r)
        st = ", ".join(f"{k} {v['seconds']:.2f} s/{v['peak_bytes'] / 2**20:.0f} MiB" for k, v in r["stages"].items())
        print(f"{kw}: {r['n_triangles']:,} triangles, {r['iterations']} it: {st}", flush=True)
        return r

    # gmsh: a small run for the fixed costs, larger ones for the cost per triangle
    run(geometry="unit_square", h=0.05, refine=0)
    for h in ((0.006,) if args.quick else (0.004, 0.0028)):
        run(geometry="unit_square", h=h, refine=0)
    # the pipeline with the default solver, up to ~1.5M triangles
    for r in range(1, top + 1):  # refine 1 (23k triangles): the NumPy paths' laws
        run(geometry="unit_square", h=0.02, refine=r)
    # other solvers at two sizes (iteration growth)
    for method, pc in (("pcg", "amg_rs"), ("pcg", "ic0"), ("pcg", "jacobi"), ("cg", None), ("direct", None)):
        for r in (1, 2) if args.quick else (2, 3):
            run(geometry="unit_square", h=0.02, refine=r, method=method, preconditioner=pc or "none",
                errors=False)
    for method in ("jacobi", "sd"):
        for h in (0.1, 0.05):
            run(geometry="unit_square", h=h, refine=0, method=method, preconditioner="none", errors=False,
                outputs=())
    for kind in ("xdmf", "png"):
        run(geometry="unit_square", h=0.02, refine=2, outputs=(kind,), errors=False)
    return runs


#: The stage of ``femkit solve`` each 3D law is fitted on (femkit/cost/tetrahedra.py).
TET_LAWS = {"mesh": "mesh", "assembly": "assembly", "boundary": "boundary", "solve_fmg": "solve",
            "errors": "errors", "estimate": "estimate"}


def fit_tetrahedra(c: dict, levels) -> dict:
    """The ``tetrahedra`` section from ``femkit solve``'s stage peaks on refined Kuhn cubes."""
    runs = []
    for k in levels:
        r = measure_case_subprocess(dict(CUBE_CASE, mesh={**CUBE_CASE["mesh"], "refine": k}))
        runs.append(r)
        peaks = ", ".join(f"{s} {v['peak_bytes'] / 2**20:.0f}" for s, v in r["stages"].items())
        print(f"refine {k}: {r['n_cells']:,} tetrahedra; stage peaks (MiB above the start): {peaks}",
              flush=True)
    small, big = sorted(runs, key=lambda r: r["n_cells"])[-2:]
    per_tet, fixed = {}, 0.0
    for law, stage in TET_LAWS.items():
        slope = ((big["stages"][stage]["peak_bytes"] - small["stages"][stage]["peak_bytes"])
                 / (big["n_cells"] - small["n_cells"]))
        per_tet[law] = round(slope, 1)
        total = big["baseline_bytes"] + big["stages"][stage]["peak_bytes"]
        fixed = max(fixed, total - slope * big["n_cells"] - c["bytes"]["baseline"])
    return {"fixed_bytes": float(f"{fixed:.3g}"), "margin": c["tetrahedra"]["margin"],
            "bytes_per_tetrahedron": per_tet}


def normalise_speed(runs: list[dict], ref: float) -> list[dict]:
    """Copies of ``runs`` with every time scaled by ``ref / run["speed_probe"]`` (the median
    speed probe just before and after the run): on a shared machine a run made while another
    job ran counts as if made at the reference speed, the one the model's ``speed`` is relative
    to (:func:`femkit.cost.machine_speed`)."""
    out = []
    for r in runs:
        f = ref / r["speed_probe"] if r.get("speed_probe") else 1.0
        r = json.loads(json.dumps(r))
        for v in r["stages"].values():
            v["seconds"] *= f
        r["setup_seconds"] *= f
        r["solve_seconds"] *= f
        out.append(r)
    return out


def fit(c: dict, runs: list[dict], min_fit: float) -> None:
    """Fill ``c`` (the constants) from the measured ``runs`` (see the module docstring)."""
    s, b = c["seconds"], c["bytes"]
    c["bytes"]["baseline"] = round(float(np.median([r["baseline_bytes"] for r in runs])), -5)
    # gmsh: fixed (import + initialise) from the smallest run, per triangle from the
    # generation-only runs
    smalls = [r for r in runs if r["n_generated"] < 2_000]  # gmsh's own time is ~0 there
    s["gmsh_fixed"] = round(float(np.median([r["stages"]["mesh"]["seconds"] for r in smalls])), 3)
    b["gmsh_import"] = round(float(np.median([r["stages"]["mesh"]["peak_bytes"] for r in smalls])), -5)
    gm = [r for r in runs if r["refine"] == 0 and r["n_generated"] >= min_fit]
    # gmsh's time grows faster than linearly: seconds = fixed + a m^p
    s["gmsh"] = power_law([r["n_generated"] for r in gm],
                          [r["stages"]["mesh"]["seconds"] - s["gmsh_fixed"] for r in gm], hi=2.0)
    b["gmsh_per_triangle"] = float(np.median([(r["stages"]["mesh"]["peak_bytes"] - b["gmsh_import"]) / r["n_generated"] for r in gm]))
    b["gmsh_retained"] = 0.0

    big = [r for r in runs if r["n_triangles"] >= min_fit]

    def per_tri(stage, sel=None, what="peak_bytes"):
        vals = []
        for r in (sel if sel is not None else big):
            if stage not in r["stages"]:
                continue
            v = r["stages"][stage][what]
            if what == "peak_bytes":
                v -= fixed_bytes(stage, **_flags(r, c))
            vals.append(v / r["n_triangles"])
        return float(np.median(vals))

    refined = [r for r in big if r["refine"] > 0]  # gmsh's own memory is small in these
    # bytes per triangle from the compiled runs (the sizes the memory guard is for: per triangle
    # the peaks shrink with the size, e.g. quality has no temporaries on the compiled path)
    large = [r for r in refined if r["n_triangles"] >= COMPILED_FROM] or refined
    for st in ("refine", "quality", "boundary", "errors", "estimate"):
        b[f"{st}_per_triangle"] = round(per_tri(st, large), 1)
    b["assembly_numpy_per_triangle"] = round(per_tri("assembly", [r for r in refined if r["n_triangles"] < COMPILED_FROM]), 1)
    b["assembly_per_triangle"] = round(per_tri("assembly", [r for r in refined if r["n_triangles"] >= COMPILED_FROM]), 1)
    # what gmsh leaves resident after a large generation (seen in the next stage, quality)
    b["gmsh_retained"] = round(float(np.median([
        (r["stages"]["quality"]["peak_bytes"] - fixed_bytes("quality", **_flags(r, c))
         - b["quality_per_triangle"] * r["n_triangles"]) / (b["gmsh_per_triangle"] * r["n_generated"])
        for r in gm])), 3)
    def time_law(stage, sel, fixed=0.0):
        sel = [r for r in sel if stage in r["stages"]]
        return power_law([r["n_triangles"] for r in sel], [r["stages"][stage]["seconds"] - fixed for r in sel])

    for st in ("errors", "estimate"):
        s[st] = time_law(st, refined)
    # refine, quality, assembly, boundary: a NumPy path below COMPILED_FROM triangles and a
    # compiled one above (per size the median over the runs: every solver's run repeats them);
    # numba's start-up (numba_load, measured with the imports) is paid in the first stage after
    # the mesh, refine in these runs
    numpy_runs = [r for r in runs if r["refine"] > 0 and NUMPY_FIT_FROM <= r["n_triangles"] < COMPILED_FROM]
    compiled = [r for r in refined if r["n_triangles"] >= COMPILED_FROM]
    for st in COMPILED_STAGES:
        s[f"{st}_numpy"] = power_law(*median_by_size(numpy_runs, st))
        sizes, secs = median_by_size(compiled, st)
        if sizes:
            start = s["numba_load"] if st == "refine" else 0.0
            s[st] = power_law(sizes, [max(t - start, 1e-3) for t in secs])
    vtu_runs = [r for r in big if r["outputs"] == ["vtu"]]
    b["output_per_triangle"] = round(per_tri("output", [r for r in vtu_runs if r in large]), 1)
    for kind in ("vtu", "xdmf", "png"):
        sel = [r for r in big if r["outputs"] == [kind]]
        # png: matplotlib's import (png_fixed, measured with the imports) is paid once per run
        s[kind] = time_law("output", sel, s["png_fixed"] if kind == "png" else 0.0)
        if kind != "png":
            c["output_bytes"][f"{kind}_per_triangle"] = round(float(np.median([r["output_bytes"] / r["n_triangles"] for r in sel])), 2)
    c["output_bytes"]["png"] = round(float(np.median([r["output_bytes"] for r in big if r["outputs"] == ["png"]])), -3)
    # solvers
    by_key: dict[str, list] = {}
    for r in runs:
        by_key.setdefault(solver_key(r["method"], r["preconditioner"]), []).append(r)
    for key, rs in by_key.items():
        rs = sorted(rs, key=lambda r: r["dofs"])
        sel = [r for r in rs if r["n_triangles"] >= min_fit] or rs[-1:]
        small_only = rs[-1]["n_triangles"] < min_fit  # memory too small to fit: set below
        sel_b = [r for r in sel if r["n_triangles"] >= COMPILED_FROM and r["refine"] > 0] or sel
        b["solve_per_triangle"][key] = None if small_only else round(float(np.median(
            [(max(r["stages"]["solve"]["peak_bytes"] - fixed_bytes("solve", **_flags(r, c)), 0))
             / r["n_triangles"] for r in sel_b])), 1)
        if key == "direct":
            # what is alive is the boundary stage's state; the LU (factors + SuperLU's work
            # space) on top of it grows like a power of the unknowns
            b["solve_per_triangle"][key] = b["boundary_per_triangle"]
            b["direct"] = power_law([r["dofs"] for r in rs],
                                    [r["stages"]["solve"]["peak_bytes"] - r["stages"]["boundary"]["peak_bytes"]
                                     for r in rs], lo=1.0, hi=2.5)
            (n1, t1), (n2, t2) = [(r["dofs"], r["setup_seconds"]) for r in rs[-2:]]
            p = math.log(t2 / t1) / math.log(n2 / n1)
            s["direct_exponent"] = round(p, 3)
            s["direct_coefficient"] = t2 / n2 ** p
            (n1, f1), (n2, f2) = [(r["dofs"], r["fill"]) for r in rs[-2:]]
            c["fill"]["direct_exponent"] = round(math.log(f2 / f1) / math.log(n2 / n1), 3)
            c["fill"]["direct_coefficient"] = f2 / n2 ** c["fill"]["direct_exponent"]
            s["direct_solve_per_fill"] = float(np.median([r["solve_seconds"] / r["fill"] for r in rs]))
            continue
        r1, r2 = rs[0], rs[-1]
        p = math.log(r2["iterations"] / r1["iterations"]) / math.log(r2["dofs"] / r1["dofs"])
        p = min(max(p, 0.0), 1.2)
        c["iterations"][key] = {"coefficient": round(r2["iterations"] / r2["dofs"] ** p, 4), "exponent": round(p, 3)}
        s["iteration_per_nonzero"][key] = float(np.median([r["solve_seconds"] / (r["iterations"] * r["nnz"]) for r in sel]))
        pc = key.split("+", 1)[1] if "+" in key else "none"
        if pc in s["setup_per_nonzero"]:
            # IC(0) starts numba in its setup when no compiled stage did (below COMPILED_FROM)
            s["setup_per_nonzero"][pc] = float(np.median([
                (r["setup_seconds"] - (s["numba_load"] if pc == "ic0" and r["n_triangles"] < COMPILED_FROM
                                       else 0.0)) / r["nnz"] for r in sel]))
    for key, v in b["solve_per_triangle"].items():
        if v is None:  # jacobi / sd hold the same vectors as cg
            b["solve_per_triangle"][key] = b["solve_per_triangle"]["cg"]
    if "cg" in c["iterations"]:
        c["iterations"]["pcg+none"] = dict(c["iterations"]["cg"])
        s["iteration_per_nonzero"]["pcg+none"] = s["iteration_per_nonzero"]["cg"]
        b["solve_per_triangle"]["pcg+none"] = b["solve_per_triangle"]["cg"]


if __name__ == "__main__":
    sys.exit(main())
