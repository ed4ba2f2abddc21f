"""The contact plan against measured runs (run by hand): ``OPENBLAS_NUM_THREADS=1 python
benchmarks/bench_contact_plan.py [--n 21 41] [--steps 40]``.

For each ``n``: the ``cloth_on_sphere`` scene (``cases/scenes/cloth_on_sphere.yaml``) at
``n x n`` vertices for ``steps`` steps, its plan as ``femkit solve`` makes it before a run
(``plan_case(measure=True)``: a measured first batch of steps and the machine's speed now), then
the run itself in this process (``femkit solve --force``); printed: the plan's measured seconds of a
contact-free step (its first batch), the surface facets, the plan's seconds (simulate + contact), the run's wall and process CPU seconds, the ratio plan / wall, Newton iterations (the
direct solver's factorisations: one an iteration) per step in contact (the frames with an active
pair) and contact's own seconds per surface facet per iteration brought to the reference speed
(``result.json``'s contact seconds / iterations / facets / the machine's speed), the two numbers
``femkit/cost/constants.json``'s ``contact`` entry is fitted to (docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

SCENE = Path(__file__).resolve().parents[1] / "cases" / "scenes" / "cloth_on_sphere.yaml"


def scene_text(n: int, steps: int) -> str:
    """The bundled scene at ``n x n`` vertices, ``steps`` steps of 0.01, every step recorded."""
    return (SCENE.read_text().replace("nx: 81", f"nx: {n}").replace("ny: 81", f"ny: {n}")
            .replace("t_end: 2.0", f"t_end: {steps * 0.01:g}"))


def one(n: int, steps: int, tmp: Path) -> dict:
    """Plan and run of one size (see the module docstring)."""
    from femkit import load_case
    from femkit.case.budget import plan_case
    from femkit.cli import main
    from femkit.cost import machine_speed

    path = tmp / f"cloth{n}.yaml"
    path.write_text(scene_text(n, steps))
    plan = plan_case(load_case(path), measure=True)
    speed = machine_speed(statistic="median")
    out = tmp / f"out{n}"
    w0, c0 = time.perf_counter(), time.process_time()
    code = main(["solve", str(path), "-o", str(out), "--quiet", "--force"])
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    speed = 0.5 * (speed + machine_speed(statistic="median"))
    r = json.loads((out / "result.json").read_text())
    iters = r["linear_solver"]["factorizations"]
    touching = sum(1 for f in r["contact"]["frames"][1:] if f["active_contacts"] > 0)
    facets = 2 * (n - 1) ** 2 + 1282
    own = sum(r["contact"]["seconds"].values())
    step = next(s for s in plan.stages if s.name == "simulate").seconds / steps
    return {"n": n, "code": code, "plan": plan.seconds, "step": step, "facets": facets,
            "wall": wall, "cpu": cpu, "speed": speed,
            "iterations": iters, "contact_steps": touching,
            "per_contact_step": (iters - 2 * (steps - touching)) / max(touching, 1),
            "facet_iteration_ref": own / iters / facets / speed}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[21, 41])
    ap.add_argument("--steps", type=int, default=40)
    args = ap.parse_args()
    print(f"{'n':>4} {'step s':>7} {'facets':>7} {'plan s':>8} {'wall s':>8} {'cpu s':>8} {'plan/wall':>9} {'speed':>6} "
          f"{'it/contact step':>15} {'s/facet/it (ref)':>16}")
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.n:
            r = one(n, args.steps, Path(tmp))
            print(f"{r['n']:>4} {r['step']:>7.3f} {r['facets']:>7} {r['plan']:>8.1f} {r['wall']:>8.1f} {r['cpu']:>8.1f} "
                  f"{r['plan'] / r['wall']:>9.2f} {r['speed']:>6.2f} "
                  f"{r['per_contact_step']:>15.1f} {r['facet_iteration_ref']:>16.2e}")


if __name__ == "__main__":
    main()
