"""One run of the ``springs_vs_elements`` study: a model on a scene's mesh, integrated in time.

A *model* is either springs (a layout of :data:`femkit.study.springs_vs_elements.layouts.SPRING_LAYOUTS` on
the mesh, stiffness fitted from ``E``, ``nu`` by Van Gelder's rule) or elements (an
:class:`~femkit.solids.ElasticBody` of a material of :data:`femkit.solids.MATERIALS`, plane
strain); both carry the same lumped masses (``density * area / 3`` per vertex), supports and
external forces, and are integrated by any registered integrator (``newton``: implicit Euler
solved by Newton; ``projective``: projective dynamics, elements only; ``fast_mass_spring``:
springs only). Every step is recorded: the scene's tracked quantity and the area
``sum det F * area`` of the mesh triangles at the deformed positions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MethodSpec", "ModelRun", "build_system", "run_model", "deformed_area"]


@dataclass(frozen=True)
class MethodSpec:
    """One entry of ``methods:``: ``model`` (``springs`` / ``elements``), ``layout`` (springs),
    ``material`` (elements), ``integrator`` (an :class:`~femkit.case.specs.IntegratorSpec`)
    and the ``label`` the report uses."""

    model: str
    layout: str | None
    material: str | None
    integrator: object
    label: str

    @property
    def springs(self) -> bool:
        return self.model == "springs"


@dataclass
class ModelRun:
    """What one run recorded: times, the tracked quantity and the area change per step, the
    integration's wall time (minimum over repeats), the node and spring/element counts."""

    times: np.ndarray
    quantity: np.ndarray
    area_change: np.ndarray
    seconds: float
    nodes: int
    parts: int
    completed: bool
    reason: str
    stats: dict


def deformed_area(triangles: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Signed areas of the triangles at positions ``x`` (``(m, n, 2)`` or ``(n, 2)``), summed."""
    a, b, c = (x[..., triangles[:, k], :] for k in range(3))
    cross = (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])
    return 0.5 * cross.sum(axis=-1)


def build_system(method: MethodSpec, mesh, pinned, forces, E: float, nu: float, density: float):
    """The dynamics system of ``method`` on ``mesh`` (springs or an elastic body)."""
    from ...dynamics.system import elastic_system
    from ...dynamics.system import MassSpringSystem
    from ...solids import ElasticBody, material
    from .layouts import SPRING_LAYOUTS, plane_strain_modulus

    if method.springs:
        from ...dynamics.topology import mesh_springs

        springs, k = SPRING_LAYOUTS.get(method.layout).build(mesh, plane_strain_modulus(E, nu))
        mass = mesh_springs(mesh, k=1.0, density=density).mass   # the one lumping rule
        return MassSpringSystem(mesh.points.copy(), mass, springs, k, pinned=pinned,
                                forces=list(forces)), len(springs)
    body = ElasticBody(mesh.points, mesh.triangles, material(method.material, E=E, nu=nu,
                                                             density=density))
    return elastic_system(body, pinned=pinned, forces=list(forces)), int(len(mesh.triangles))


def run_model(method: MethodSpec, scene, params, mesh, h: float, material: dict, *,
              repeats: int = 1, stop=None) -> ModelRun:
    """Integrate ``method`` on ``mesh`` of ``scene`` (parameters ``params``) to ``t_end``,
    ``repeats`` times (the minimum wall time is kept; the trajectory is the same)."""
    from ...dynamics.integrators import StepContext
    from ...dynamics.simulate import simulate

    E, nu, rho = float(material["E"]), float(material["nu"]), float(material["density"])
    dt, t_end = float(params["dt"]), float(params["t_end"])
    best, traj = np.inf, None
    for _ in range(max(1, int(repeats))):
        system, parts = build_system(method, mesh, scene.pinned(mesh, params),
                                     scene.forces(params, h), E, nu, rho)
        traj = simulate(system, method.integrator.build(), dt, t_end, ctx=StepContext(),
                        record_every=1, energy_growth_limit=np.inf, check_stability=False,
                        stop=stop)
        best = min(best, float(traj.wall_time))
    q = scene.quantity(mesh, params)
    x = np.asarray(traj.x)
    area = deformed_area(np.asarray(mesh.triangles), x)
    return ModelRun(np.asarray(traj.times, float), np.array([q(xi) for xi in x]),
                    area / area[0] - 1.0, best, int(mesh.n_points), parts,
                    bool(traj.completed), str(traj.reason or ""), dict(traj.stats))
