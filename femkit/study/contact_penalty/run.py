"""``kind: contact_penalty``: how far penalty contact lets a body through, against barrier contact.

The scene: an ``n x n`` cloth (``femkit.dynamics.topology.cloth_grid``, horizontal, unpinned)
dropped from ``height`` onto the ground ``z = 0`` under gravity, integrated by ``newton``
(implicit Euler as a minimisation) with the same ``dt`` in every run. Each penalty stiffness
``k_c`` (the ``ground`` force: a spring ``k_c p`` on every penetrating particle, Schlögl's
penalty collisions) gives a maximum penetration ``max_t max_i (-z_i)``, falling roughly as
``1 / k_c`` at rest (``m g / k_c`` per particle) and as ``1 / sqrt(k_c)`` on impact (the kinetic
energy stored in the spring). Barrier contact (IPC, Li et al. 2020, through ipctk) runs the same
drop: its penetration is 0 by construction and its smallest gap stays > 0, which the records
report beside the penalty curve.
"""

from __future__ import annotations

import numpy as np

__all__ = ["run", "drop"]


def drop(spec, penalty: float | None) -> dict:
    """One drop: penalty ground of stiffness ``penalty``, or barrier contact (None)."""
    from ...contact import plane_obstacle
    from ...dynamics import topology
    from ...dynamics.forces import BarrierContact, Gravity, GroundContact
    from ...dynamics.integrators import INTEGRATORS, StepContext
    from ...mesh import grid_triangles

    n = spec.n
    forces = [Gravity(9.81)]
    if penalty is not None:
        forces.append(GroundContact(penalty))
    system = topology.cloth_grid(n, n, 0.5, 0.5, k_structural=500.0, k_shear=100.0,
                                 total_mass=0.1, plane="xy", pinned="none",
                                 origin=[0.0, 0.0, spec.height], forces=forces)
    if penalty is None:
        system.attach(BarrierContact(grid_triangles(n, n),
                                     [plane_obstacle([0.25, 0.25, 0.0], [0, 0, 1], 5.0, 3)]))
    integ = INTEGRATORS.get("newton")(tol=1e-6)
    ctx = StepContext()
    st = integ.start(system, system.x0, system.v0, 0.0, spec.dt, ctx)
    zmin = []
    for _ in range(max(1, round(spec.t_end / spec.dt))):
        st = integ.step(system, st, spec.dt, ctx)
        zmin.append(float(st.x[:, 2].min()))
    out = {"method": "penalty" if penalty is not None else "barrier",
           "stiffness": penalty, "max_penetration": max(0.0, -min(zmin)),
           "min_height": min(zmin), "newton_iterations": int(np.sum(ctx.stats["newton_iterations"]))}
    if penalty is None:
        f = system.forces[-1].model
        out["stiffness"] = f.kappa_value
        out["intersections"] = f.intersections(st.x)
    return out


def run(study, progress_enabled=None) -> dict:
    """Every penalty stiffness, then barrier contact: the records."""
    spec = study.spec
    records = [drop(spec, k) for k in spec.stiffnesses]
    records.append(drop(spec, None))
    return {"records": records}
