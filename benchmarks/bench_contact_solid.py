"""Barrier contact on a tetrahedral solid (run by hand): ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_contact_solid.py [--cells 56 8 8] [--steps 4]``.

A stable neo-Hookean bar (``--cells nx ny nz`` cubes of edge 0.05 on
:func:`femkit.mesh.structured.structured_box`, six tetrahedra each: 56 x 8 x 8 = 21,504
tetrahedra) lying on the ground at half the barrier's activation distance, compressed end-on
(initial velocity ``-2 (x - L/2) / L`` m/s along the bar: both ends run at the middle at 1 m/s)
under gravity; ``newton`` (implicit Euler, IPC's tolerance ``||dx||_inf <= 1e-2 h L``),
``direct`` solves (SuperLU), dt 0.01. Run twice in one process with the same integrator:

* **contact**: barrier contact (IPC through ipctk) on the bar's whole boundary surface with
  self-contact on (its broad phase and CCD cover every surface pair of the bar, not only the
  ground's) and the ground plane as an obstacle;
* **free**: the same bar without the contact force (the contact-free step, the peer).

Printed: seconds per step (process CPU seconds, ipctk on one thread as femkit's step is; wall
seconds too), steps per second, Newton iterations per step, the contact run's split among the
broad phase, CCD and the barrier Hessian (``BarrierModel.seconds``), the active contact pairs and
minimum distance at the end, and the independent intersection test (:mod:`femkit.contact.check`)
on every step's state. The first step of each run is not timed (compilations, first analyses).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np


def build(cells, contact: bool):
    """The bar's system (and its BarrierContact force, or None)."""
    from femkit.contact import body_surface, plane_obstacle
    from femkit.dynamics.forces import BarrierContact, Gravity
    from femkit.dynamics.system import elastic_system
    from femkit.mesh.structured import structured_box
    from femkit.solids import ElasticBody, material

    nx, ny, nz = cells
    h = 0.05
    length = nx * h
    mesh = structured_box(nx, ny, nz, (length, ny * h, nz * h))
    body = ElasticBody.from_mesh(mesh, material("stable_neo_hookean", E=2e5, nu=0.3, density=1e3))
    P = mesh.points.copy()
    diag = float(np.linalg.norm(np.ptp(P, axis=0)))
    P[:, 2] += 0.5e-3 * diag                       # at dhat / 2 (dhat = 1e-3 of the diagonal)
    v0 = np.zeros_like(P)
    v0[:, 0] = -2.0 * (P[:, 0] - length / 2) / length
    forces = [Gravity(9.81)]
    force = None
    if contact:
        ground = plane_obstacle([length / 2, ny * h / 2, 0.0], [0, 0, 1], 2 * length, 3)
        force = BarrierContact(body_surface(mesh.cells, 3), [ground], self_contact=True)
        forces.append(force)
    system = elastic_system(body, x0=P, v0=v0, forces=forces)
    if contact:   # the system's own (bound) copy
        force = next(f for f in system.forces if isinstance(f, BarrierContact))
    return system, force, mesh.n_cells


def run(cells, steps: int, contact: bool) -> dict:
    """CPU and wall seconds per step, Newton iterations, (contact) the split and the checks."""
    from femkit.dynamics.integrators import StepContext, get_integrator
    from femkit.solvers.spec import SolverSpec

    system, force, n_cells = build(cells, contact)
    dt = 0.01
    integ = get_integrator("newton", tol=1e-2 * dt, max_iterations=60)
    ctx = StepContext(SolverSpec("direct"))
    st = integ.start(system, system.x0, system.v0, 0.0, dt, ctx)
    cpu, wall, checked = [], [], 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k in range(steps + 1):   # the first step (compilations, first analyses) untimed
            c0, w0 = time.process_time(), time.perf_counter()
            st = integ.step(system, st, dt, ctx)
            if k == 0 and force is not None:
                split0 = dict(force.model.seconds)
            if k:
                cpu.append(time.process_time() - c0)
                wall.append(time.perf_counter() - w0)
            if force is not None:
                checked += force.model.intersections(st.x)
    out = {"cells": n_cells, "dofs": system.x0.size, "cpu": float(np.mean(cpu)),
           "wall": float(np.mean(wall)), "iterations": float(np.mean(ctx.stats["newton_iterations"][1:])),
           "unconverged": int(ctx.stats.get("unconverged_steps", 0))}
    if force is not None:
        m = force.model
        out.update(split={k: (v - split0[k]) / steps for k, v in m.seconds.items()}, active=m.active(st.x),
                   min_distance=m.min_distance(st.x), intersections=checked,
                   surface=len(force.surface))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, nargs=3, default=[56, 8, 8], metavar=("NX", "NY", "NZ"))
    ap.add_argument("--steps", type=int, default=4)
    args = ap.parse_args()
    import ipctk

    from femkit.contact.barrier import BarrierModel

    ipctk.set_num_threads(1)   # CPU seconds of one thread, as the contact-free step
    BarrierModel.clock = staticmethod(time.process_time)
    free = run(args.cells, args.steps, False)
    con = run(args.cells, args.steps, True)
    print(f"bar {' x '.join(map(str, args.cells))} cubes: {con['cells']:,} tetrahedra, "
          f"{con['dofs']:,} dofs, {con['surface']:,} surface triangles; {args.steps} steps of 0.01 "
          "timed after an untimed first")
    for name, r in (("contact-free", free), ("barrier contact", con)):
        late = f", {r['unconverged']} unconverged" if r["unconverged"] else ""
        print(f"  {name:16s} {r['cpu']:7.2f} s/step CPU ({1 / r['cpu']:.3f} steps/s; wall "
              f"{r['wall']:.2f} s), {r['iterations']:4.1f} Newton iterations/step"
              f"{late}")
    print(f"  ratio contact / free: {con['cpu'] / free['cpu']:.2f}")
    rest = con["cpu"] - sum(con["split"].values())
    print("  split of a contact step: " + ", ".join(
        f"{k} {v:.3f} s" for k, v in con["split"].items()) + f", Newton rest {rest:.3f} s")
    print(f"  at the end: {con['active']} active pairs, minimum distance {con['min_distance']}; "
          f"intersecting pairs over all steps (femkit.contact.check): {con['intersections']}")


if __name__ == "__main__":
    main()
