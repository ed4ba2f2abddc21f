"""Barrier contact benchmark (run by hand): ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_contact.py [--n 41] [--steps 25]``.

The ``cloth_on_sphere`` scene (``cases/scenes/cloth_on_sphere.yaml``: a cloth dropped on a sphere
resting on the ground, self-contact, friction 0.2) at ``n x n`` vertices, run twice in one
process with the same ``newton`` integrator, dt and tolerance:

* **contact**: barrier contact on (IPC through ipctk);
* **free**: the same cloth without ``contact:`` (it falls through the sphere; the contact-free
  Newton step, the peer of the ratio);
* **penalty**: the sphere and the ground as penalty forces (``--penalty`` stiffness, 1e3 by
  default) instead of barrier contact, no self-contact: the same draping and folding with
  neither barrier nor CCD, to tell the Newton iterations the deformation needs from those the
  barrier adds.

For each: the seconds per step over the steps after the first contact (the steps before it are
cheap in both) -- process CPU seconds, with ipctk held to one thread as femkit's contact-free
step is (on a shared machine wall time follows the load; the wall seconds are printed too) --,
Newton iterations per step, and for the contact run the split of its time among
the collision broad phase (``NormalCollisions.build``), CCD (``compute_collision_free_stepsize``)
and the barrier/friction Hessian (``BarrierModel.seconds``); the rest is the Newton step itself
(springs, the linear solves), and per Newton iteration the cost of each run, the barrier's Newton
rest, and the evaluations of the step's objective (``system.energies`` calls) and the CCD calls. All
counters are read before the first step in contact, which is measured whole. The issue's bar is a
contact step at most 3x the contact-free one.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np


SCENE = Path(__file__).resolve().parents[1] / "cases" / "scenes" / "cloth_on_sphere.yaml"


def run(n: int, steps: int, contact: bool, tmp: Path, penalty: float = 0.0,
        ccd: str = "tight_inclusion", solver: str = "direct") -> dict:
    """Seconds per step after the first contact, Newton iterations and (contact) the split;
    ``penalty > 0`` (with ``contact=False``): the sphere and the ground as penalty forces of
    that stiffness instead (the same draping without barrier or CCD)."""
    import yaml

    from femkit import load_case
    from femkit.case.scene.run import build_context, build_integrator, build_system, contact_force

    data = yaml.safe_load(SCENE.read_text())
    data["system"].update(nx=n, ny=n)
    if solver != "direct":
        data["linear_solver"] = {"method": "cholesky", "options": {"engine": solver}}
    if not contact:
        data.pop("contact")
    else:
        data["contact"]["ccd"] = ccd
    if penalty:
        data["forces"] = {"gravity": data["forces"]["gravity"],
                          "ground": {"height": 0.0, "stiffness": penalty},
                          "sphere": {"centre": [0.5, 0.5, 0.25], "radius": 0.25,
                                     "stiffness": penalty}}
    path = tmp / f"scene_{int(contact)}_{int(penalty > 0)}.yaml"
    path.write_text(yaml.safe_dump(data))
    case = load_case(path)
    system, _ = build_system(case)
    integ, ctx = build_integrator(case), build_context(case)
    f = contact_force(system)
    st = integ.start(system, system.x0, system.v0, 0.0, case.spec.dt, ctx)
    calls = _count_calls(system, "energies")   # one per evaluation of newton's objective
    times, walls, split0, first = [], [], None, None
    for k in range(steps):
        # the counters before the step: the first step in contact is measured whole
        before = (None if f is None else dict(f.model.seconds),
                  (calls[0], 0 if f is None else f.model.stats["ccd_calls"]))
        t0, w0 = time.process_time(), time.perf_counter()
        st = integ.step(system, st, case.spec.dt, ctx)
        times.append(time.process_time() - t0)
        walls.append(time.perf_counter() - w0)
        touching = st.x[:, 2].min() < 0.51 if f is None else f.model.active(st.x) > 0
        if first is None and touching:
            first, (split0, counts0) = k, before
    if first is None:   # no contact in these steps: all of them measured
        first, split0 = 0, None if f is None else {k: 0.0 for k in f.model.seconds}
        counts0 = (0, 0)
    after = np.array(times[first:])
    its = ctx.stats["newton_iterations"][first:]
    out = {"per_step": float(after.mean()), "wall": float(np.mean(walls[first:] or walls)), "iterations": float(np.mean(its)) if its else 0.0,
           "steps_measured": len(after), "first_contact_step": first}
    n_its = max(sum(its), 1)
    out["objective_per_iteration"] = (calls[0] - counts0[0]) / n_its
    if f is not None:
        out["ccd_per_iteration"] = (f.model.stats["ccd_calls"] - counts0[1]) / n_its
        sec = f.model.seconds
        out["split"] = {k: (sec[k] - split0[k]) / max(len(after), 1) for k in sec}
    return out


def _count_calls(obj, name: str) -> list:
    """Count the calls of ``obj.name`` from now on (``[count]``, updated in place)."""
    calls, method = [0], getattr(obj, name)

    def counted(*args, **kwargs):
        calls[0] += 1
        return method(*args, **kwargs)

    setattr(obj, name, counted)
    return calls


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=41, help="cloth vertices per side (81: the scene)")
    ap.add_argument("--steps", type=int, default=25)
    ap.add_argument("--penalty", type=float, default=1e3,
                    help="stiffness of the penalty run's sphere and ground")
    ap.add_argument("--ccd", default="tight_inclusion", choices=["tight_inclusion", "additive"],
                    help="the contact run's narrow-phase CCD (contact.ccd)")
    ap.add_argument("--solver", default="direct", choices=["direct", "cholespy", "cholmod"],
                    help="every run's Newton factorisation: SuperLU or CHOLMOD (the cholespy wheel, or scikit-sparse)")
    args = ap.parse_args()
    import ipctk

    from femkit.contact.barrier import BarrierModel

    ipctk.set_num_threads(1)   # CPU seconds of one thread, as the contact-free step
    BarrierModel.clock = staticmethod(time.process_time)
    with tempfile.TemporaryDirectory() as tmp:
        free = run(args.n, args.steps, False, Path(tmp), solver=args.solver)
        pen = run(args.n, args.steps, False, Path(tmp), penalty=args.penalty, solver=args.solver)
        con = run(args.n, args.steps, True, Path(tmp), ccd=args.ccd, solver=args.solver)
    print(f"cloth {args.n} x {args.n}, {args.steps} steps, measured from the first contact; "
          f"CCD {args.ccd}, solver {args.solver}")
    for name, r in (("contact-free", free), ("penalty contact", pen), ("barrier contact", con)):
        print(f"  {name:16s} {1e3 * r['per_step']:9.1f} ms/step, {r['iterations']:5.1f} Newton "
              f"iterations/step ({r['steps_measured']} steps; wall {1e3 * r['wall']:.1f} ms/step)")
    print(f"  ratio contact / free: {con['per_step'] / free['per_step']:.2f} (bar: <= 3); "
          f"contact / penalty: {con['per_step'] / pen['per_step']:.2f}")
    rest = con["per_step"] - sum(con["split"].values())
    print("  split of a contact step: " + ", ".join(
        f"{k} {1e3 * v:.1f} ms" for k, v in con["split"].items()) + f", Newton rest {1e3 * rest:.1f} ms")
    print(f"  per Newton iteration: contact-free {1e3 * free['per_step'] / free['iterations']:.1f} ms, "
          f"penalty {1e3 * pen['per_step'] / pen['iterations']:.1f} ms, barrier {1e3 * con['per_step'] / con['iterations']:.1f} ms "
          f"(its Newton rest {1e3 * rest / con['iterations']:.1f} ms); objective evaluations per "
          f"iteration: free {free['objective_per_iteration']:.2f}, penalty "
          f"{pen['objective_per_iteration']:.2f}, barrier {con['objective_per_iteration']:.2f} "
          f"(CCD calls {con['ccd_per_iteration']:.2f})")


if __name__ == "__main__":
    main()
