"""Barrier contact on a tetrahedral solid (run by hand): ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_contact_solid.py [--cells 371 3 3] [--steps 4]``.

A compressed coil spring with self-contact: a stable neo-Hookean wire of ``--cells nx ny nz``
cubes of edge 0.03 (:func:`femkit.mesh.structured.structured_box`, six tetrahedra each:
371 x 3 x 3 = 20,034 tetrahedra), wound as its rest shape on a helix of radius 0.25 (about 7
turns), the turns half the barrier's activation distance apart (``dhat / 2``, ``dhat`` 1e-3 of
the bounding-box diagonal), pressed together end-on (initial velocity
``-2 (z - z_mean) / height`` m/s: both ends at 1 m/s towards the middle), no gravity;
``newton`` (implicit Euler, IPC's tolerance ``||dx||_inf / h <= 1e-2 L``), ``direct`` solves
(SuperLU), dt 0.01. Run twice in one process with the same integrator:

* **contact**: barrier contact (IPC through ipctk) on the coil's boundary surface with
  self-contact on: every turn touches its neighbours through the barrier from the first step;
* **free**: the same coil without the contact force (its turns pass through each other; the
  contact-free step, the peer).

Printed: seconds per step (process CPU seconds, ipctk on one thread as femkit's step is; wall
seconds too), steps per second, Newton iterations per step, the contact run's split among the
broad phase, CCD and the barrier Hessian (``BarrierModel.seconds``), the active contact pairs after
each step, the minimum distance at the end, and the independent intersection test (:mod:`femkit.contact.check`)
on every step's state. The first step of each run is not timed (compilations, first analyses).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np


def coil(cells, h: float, radius: float, gap: float):
    """Points and positively oriented tetrahedra of a coil spring: a box of ``cells`` cubes of
    edge ``h`` (its long side ``x`` the wire) wound on a helix of ``radius`` whose turns lie
    ``gap`` apart (the rest shape: no prestress)."""
    from femkit.mesh.structured import structured_box

    nx, ny, nz = cells
    mesh = structured_box(nx, ny, nz, (nx * h, ny * h, nz * h))
    u, v, w = mesh.points.T
    v, w = v - ny * h / 2, w - nz * h / 2
    theta = u / radius
    pitch = nz * h + gap
    P = np.stack([(radius + v) * np.cos(theta), (radius + v) * np.sin(theta),
                  pitch * theta / (2 * np.pi) + w], axis=1)
    T = np.array(mesh.cells)
    a, b, c, d = (P[T[:, i]] for i in range(4))
    neg = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    T[neg] = T[neg][:, [0, 2, 1, 3]]
    return P, T


def build(cells, contact: bool):
    """The coil's system (and its BarrierContact force, or None)."""
    from femkit.contact import body_surface
    from femkit.dynamics.forces import BarrierContact
    from femkit.dynamics.system import elastic_system
    from femkit.solids import ElasticBody, material

    P, T = coil(cells, 0.03, 0.25, 0.0)
    diag = float(np.linalg.norm(np.ptp(P, axis=0)))
    gap = 0.5e-3 * diag                            # the turns at dhat / 2 (dhat: 1e-3 diagonal)
    P, T = coil(cells, 0.03, 0.25, gap)
    body = ElasticBody(P, T, material("stable_neo_hookean", E=2e5, nu=0.3, density=1e3))
    z = P[:, 2]
    v0 = np.zeros_like(P)
    v0[:, 2] = -2.0 * (z - z.mean()) / np.ptp(z)   # ends pressed at the middle at 1 m/s
    forces = []
    if contact:
        forces.append(BarrierContact(body_surface(T, 3), [], self_contact=True))
    system = elastic_system(body, x0=P, v0=v0, forces=forces)
    force = next((f for f in system.forces if isinstance(f, BarrierContact)), None)
    return system, force, len(T)


def run(cells, steps: int, contact: bool, solver: str = "direct") -> dict:
    """CPU and wall seconds per step, Newton iterations, (contact) the split and the checks."""
    from femkit.dynamics.integrators import StepContext, get_integrator
    from femkit.solvers.spec import SolverSpec

    system, force, n_cells = build(cells, contact)
    dt = 0.01
    integ = get_integrator("newton", tol=1e-2 * dt, max_iterations=60)
    ctx = StepContext(SolverSpec("direct") if solver == "direct"
                      else SolverSpec("cholesky", options={"engine": solver}))
    st = integ.start(system, system.x0, system.v0, 0.0, dt, ctx)
    cpu, wall, checked, active = [], [], 0, []
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
                active.append(force.model.active(st.x))
    out = {"cells": n_cells, "dofs": system.x0.size, "cpu": float(np.mean(cpu)),
           "wall": float(np.mean(wall)), "iterations": float(np.mean(ctx.stats["newton_iterations"][1:])),
           "unconverged": int(ctx.stats.get("unconverged_steps", 0))}
    if force is not None:
        m = force.model
        out.update(split={k: (v - split0[k]) / steps for k, v in m.seconds.items()}, active=active,
                   min_distance=m.min_distance(st.x), intersections=checked,
                   surface=len(force.surface))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, nargs=3, default=[371, 3, 3], metavar=("NX", "NY", "NZ"))
    ap.add_argument("--steps", type=int, default=4)
    ap.add_argument("--solver", default="direct", choices=["direct", "cholespy", "cholmod"],
                    help="the Newton systems' factorisation: SuperLU or CHOLMOD (the cholespy wheel, or scikit-sparse)")
    args = ap.parse_args()
    import ipctk

    from femkit.contact.barrier import BarrierModel

    ipctk.set_num_threads(1)   # CPU seconds of one thread, as the contact-free step
    BarrierModel.clock = staticmethod(time.process_time)
    free = run(args.cells, args.steps, False, args.solver)
    con = run(args.cells, args.steps, True, args.solver)
    print(f"coil of {' x '.join(map(str, args.cells))} cubes: {con['cells']:,} tetrahedra, "
          f"{con['dofs']:,} dofs, {con['surface']:,} surface triangles; {args.steps} steps of 0.01 "
          ""
          f"timed after an untimed first; solver {args.solver}")
    for name, r in (("contact-free", free), ("barrier contact", con)):
        late = f", {r['unconverged']} unconverged" if r["unconverged"] else ""
        print(f"  {name:16s} {r['cpu']:7.2f} s/step CPU ({1 / r['cpu']:.3f} steps/s; wall "
              f"{r['wall']:.2f} s), {r['iterations']:4.1f} Newton iterations/step"
              f"{late}")
    print(f"  ratio contact / free: {con['cpu'] / free['cpu']:.2f}")
    rest = con["cpu"] - sum(con["split"].values())
    print("  split of a contact step: " + ", ".join(
        f"{k} {v:.3f} s" for k, v in con["split"].items()) + f", Newton rest {rest:.3f} s")
    print(f"  active pairs after each step: {con['active']}; minimum distance at the end "
          f"{con['min_distance']}; "
          f"intersecting pairs over all steps (femkit.contact.check): {con['intersections']}")


if __name__ == "__main__":
    main()
