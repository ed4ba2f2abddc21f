"""The mesh stage of ``femkit solve`` alone: build the refined mesh (and the multigrid
hierarchy) and its quality numbers, as the case pipeline does, in a fresh process.

Usage (one thread; compare two trees by running it with each on ``PYTHONPATH``, alternating)::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_mesh_stage.py --case 2d --levels 6
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_mesh_stage.py --case 3d --levels 4 5

``2d``: the fmg case of ``bench_pipeline.py`` (gmsh unit square h = 0.05 refined ``k`` times; k = 6:
1.93M unknowns, renumbered). ``3d``: the case of ``bench_poisson3d.py`` (``kuhn_cube`` h = 1/3
refined ``k`` times; k = 4: 117,649 nodes, k = 5: 912,673 nodes, 5.3M tetrahedra; ``--coarse 5``
with k = 5: 4.17M nodes). numba's start-up (a stage of its own in ``femkit solve``) is paid before
the clock starts. Printed per size: the build (generation, refinement, numbering, hierarchy) and
quality seconds, the best of ``--repeat`` fresh processes.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

CASES = {
    "2d": """problem: poisson
name: mesh_stage_2d
mesh: {{geometry: unit_square, h: 0.05, refine: {k}}}
source: "1"
boundary:
  dirichlet: [{{tags: [boundary], value: 0}}]
solver: {{method: fmg}}
""",
    "3d": """problem: poisson
name: mesh_stage_3d
mesh: {{geometry: kuhn_cube, h: {h}, refine: {k}}}
source: "1"
boundary:
  dirichlet: [{{tags: [boundary], value: 0}}]
solver: {{method: fmg}}
""",
}

CHILD = """
import json, sys, time
from numba.core.registry import cpu_target
from femkit.case.load import load_case
from femkit.case.poisson.problem import build_mesh_levels
from femkit.mesh import quality
cpu_target.target_context.refresh()  # numba's start-up: the pipeline's own stage
case = load_case(sys.argv[1]).with_options(force=True)  # a benchmark of the stage: past the memory guard
t0 = time.perf_counter()
mesh, hierarchy = build_mesh_levels(case)
t1 = time.perf_counter()
quality(mesh)
t2 = time.perf_counter()
print(json.dumps({"build": t1 - t0, "quality": t2 - t1, "cells": mesh.n_cells,
                  "nodes": mesh.n_points}))
"""


def run(case: Path) -> dict:
    out = subprocess.run([sys.executable, "-c", CHILD, str(case)], capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(out.stderr.strip().splitlines()[-1])
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", choices=tuple(CASES), default="2d")
    ap.add_argument("--levels", type=int, nargs="+", default=[6])
    ap.add_argument("--coarse", type=int, default=3, help="3d: cubes per side of the coarse mesh")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="mesh-stage-"))
    for k in args.levels:
        case = tmp / f"{args.case}_{k}.yaml"
        case.write_text(CASES[args.case].format(k=k, h=repr(1.0 / args.coarse)))
        run(case)  # compiles or loads the kernels once
        rows = sorted((run(case) for _ in range(args.repeat)),
                      key=lambda r: r["build"] + r["quality"])
        best = rows[0]
        print(f"{args.case} k = {k}: {best['nodes']:,} nodes, {best['cells']:,} cells: mesh stage "
              f"{best['build'] + best['quality']:.2f} s (build {best['build']:.2f}, quality "
              f"{best['quality']:.2f}; best of {args.repeat})")


if __name__ == "__main__":
    main()
