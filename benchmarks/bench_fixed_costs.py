"""The fixed costs of ``femkit solve`` (issue 19): start-up and imports, numba's start-up, "other"
and the process's exit, for one or more source trees, runs alternated, medians.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_fixed_costs.py --tree before=/path/to/old \\
        --tree after=. --runs 5 --levels 5

Each tree is put first on ``PYTHONPATH`` and runs ``python -m femkit solve`` of
``bench_pipeline.py``'s fmg case (``--levels`` refinements of the h = 0.05 square: 5 gives
482,049 unknowns) as a fresh process, the trees taking turns (one run of each, then the next
round), so a machine's changing load falls on every tree alike. Run ``femkit warmup`` with each
tree first (its kernels cached; the new warm-up also writes femkit's bytecode). Columns, from
``result.json``'s ``wall`` and ``timings`` and the parent's clock around the process:

* ``process``: the process's wall time (fork to exit, as the parent sees it);
* ``startup``: interpreter, imports and reading the case, before the first stage;
* ``numba``: numba's start-up stage (a tree without it pays numba's first load inside ``mesh``);
* ``other``: time between the stages; ``exit``: ``process`` - ``wall.total`` (after
  ``result.json``: the summary, freeing the run, the interpreter's exit);
* ``fixed``: ``startup + numba + other + exit``; ``fixed+mesh`` adds the mesh stage, comparable
  between trees that book numba's load in different places.

``PYTHONDONTWRITEBYTECODE=1`` is set for every run (as on a machine that sets it, or a
read-only install): what is not byte-compiled ahead is compiled from source by every run.
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_pipeline import CASE, H0, SOLVERS  # noqa: E402

COLUMNS = ("process", "startup", "numba", "other", "exit", "fixed", "mesh", "fixed+mesh")


def one_run(tree: Path, case: Path, out: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree), PYTHONDONTWRITEBYTECODE="1")
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "femkit", "solve", str(case), "--force", "--quiet",
                           "--output", str(out)], env=env, capture_output=True, text=True,
                          cwd=case.parent)  # not the caller's folder: `-m` puts it first on sys.path
    process = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"{tree}: exit {proc.returncode}: {proc.stderr.strip()}")
    res = json.loads((out / "result.json").read_text())
    wall, stages = res["wall"], res["timings"]
    row = {"process": process, "startup": wall["startup"], "numba": stages.get("numba", 0.0),
           "other": wall["other"], "exit": process - wall["total"], "mesh": stages.get("mesh", 0.0)}
    row["fixed"] = row["startup"] + row["numba"] + row["other"] + row["exit"]
    row["fixed+mesh"] = row["fixed"] + row["mesh"]
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tree", action="append", required=True, metavar="NAME=PATH",
                    help="a source tree (the folder holding femkit/), repeatable")
    ap.add_argument("--runs", type=int, default=5, help="runs per tree (default 5)")
    ap.add_argument("--levels", type=int, default=5, help="refinements (default 5: 0.48M unknowns)")
    args = ap.parse_args()
    trees = {name: Path(path).resolve() for name, path in (t.split("=", 1) for t in args.tree)}
    with tempfile.TemporaryDirectory() as tmp:
        case = Path(tmp) / "fmg.yaml"
        case.write_text(CASE.format(name=f"fmg_{args.levels}", h=H0, k=args.levels,
                                    solver=SOLVERS["fmg"]))
        rows: dict[str, list[dict]] = {name: [] for name in trees}
        for r in range(args.runs):
            for name, tree in trees.items():
                row = one_run(tree, case, Path(tmp) / f"out_{name}")
                rows[name].append(row)
                print(f"run {r + 1} {name:>10}: " + " ".join(f"{c} {row[c]:.3f}" for c in COLUMNS),
                      flush=True)
    print(f"\nmedians of {args.runs} runs (s), load average {os.getloadavg()[0]:.1f}:")
    print("| tree | " + " | ".join(COLUMNS) + " |")
    print("|---" * (len(COLUMNS) + 1) + "|")
    for name, rs in rows.items():
        print(f"| {name} | " + " | ".join(f"{statistics.median(x[c] for x in rs):.3f}" for c in COLUMNS)
              + " |")


if __name__ == "__main__":
    main()
