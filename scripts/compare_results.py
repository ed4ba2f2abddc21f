"""Compare every number of every bundled file's ``result.json`` between two femkit checkouts.

A refactoring claims "the numbers are unchanged": this script is the evidence. It runs each bundled
case and scene (``cases/**/*.yaml``) with ``femkit solve`` and each study (``studies/*.yaml``) with
``femkit study --quick`` in both checkouts (each with its own Python path and kernel cache), then
compares the two ``result.json`` files key by key: numbers must be bit-identical except under the
timing-only keys listed in :data:`TIMING_KEYS` (wall times and anything derived from them), which are
reported as skipped.

Usage::

    git worktree add /tmp/femkit-before main~5
    python scripts/compare_results.py /tmp/femkit-before .            # every bundled file
    python scripts/compare_results.py /tmp/femkit-before . cases/cube.yaml studies/solid_load.yaml

Exit status 0 when every compared number agrees, 1 otherwise (each difference printed with its key).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

#: Keys whose values measure time (or follow from a measured time): never compared.
TIMING_KEYS = ("time", "times", "seconds", "wall", "elapsed", "timings", "stages", "cpu",
               "per_step", "rate", "throughput", "date", "started", "finished", "peak_rss",
               "memory", "version", "python", "platform", "host", "machine", "cache",
               "pareto")  # studies: stage times t_*, and the Pareto flags ranked by them


#: Keys that name simulated time or a time limit, compared like any number.
SIMULATED = ("t_end", "t_reached", "t_start", "dt", "max_time", "time_budget")


def is_timing(key: str) -> bool:
    """Whether ``key`` names a measured (run-dependent) quantity."""
    low = key.lower()
    if low in SIMULATED:
        return False
    return low.startswith("t_") or any(part in low for part in TIMING_KEYS)


def compare(a, b, path: str = "") -> tuple[list[str], list[str]]:
    """Differences and skipped timing keys between two JSON values, recursively."""
    diffs: list[str] = []
    skipped: list[str] = []
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            sub = f"{path}.{key}" if path else str(key)
            if is_timing(str(key)):
                skipped.append(sub)
            elif key not in a or key not in b:
                diffs.append(f"{sub}: only in {'after' if key in b else 'before'}")
            else:
                d, s = compare(a[key], b[key], sub)
                diffs += d
                skipped += s
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            diffs.append(f"{path}: length {len(a)} != {len(b)}")
        for i, (x, y) in enumerate(zip(a, b)):
            d, s = compare(x, y, f"{path}[{i}]")
            diffs += d
            skipped += s
    elif isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        pass
    elif a != b or type(a) is not type(b):
        if not (isinstance(a, str) and isinstance(b, str) and ("/" in a or "\\" in a)):  # paths
            diffs.append(f"{path}: {a!r} != {b!r}")
    return diffs, skipped


def run(checkout: Path, target: Path, out: Path, cache: Path) -> dict | None:
    """Run one bundled file in ``checkout``; its result.json, or None when the run wrote none."""
    env = dict(os.environ, PYTHONPATH=str(checkout), FEMKIT_CACHE_DIR=str(cache),
               OPENBLAS_NUM_THREADS="1", MPLBACKEND="Agg")
    command = ["study", str(target), "--quick"] if target.parent.name == "studies" else [
        "solve", str(target)]
    subprocess.run([sys.executable, "-m", "femkit", *command, "--output", str(out)], cwd=checkout,
                   env=env, capture_output=True, text=True)
    for name in ("result.json", "results.json"):  # a case's / a study's
        if (out / name).is_file():
            return json.loads((out / name).read_text())
    return None


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument("files", nargs="*", help="bundled files (relative to a checkout); default: all")
    args = parser.parse_args(argv)
    before, after = args.before.resolve(), args.after.resolve()
    files = args.files or sorted(str(p.relative_to(after)) for p in
                                 [*after.glob("cases/**/*.yaml"), *after.glob("studies/*.yaml")])
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name in files:
            results = [run(root, root / name, tmp / side / name, tmp / f"cache-{side}")
                       for side, root in (("before", before), ("after", after))]
            if results[0] is None or results[1] is None:
                same = results[0] is None and results[1] is None
                print(f"{'same' if same else 'DIFF'}  {name}: result.json written "
                      f"before={results[0] is not None} after={results[1] is not None}")
                failed += not same
                continue
            diffs, skipped = compare(*results)
            print(f"{'same' if not diffs else 'DIFF'}  {name}: {len(diffs)} differences, "
                  f"{len(skipped)} timing-only keys skipped")
            if skipped:
                print(f"      timing-only: {', '.join(sorted({k.split('.')[-1] for k in skipped}))}")
            for line in diffs[:20]:
                print(f"      {line}")
            failed += bool(diffs)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
