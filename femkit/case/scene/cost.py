"""The cost of a ``problem: mass_spring`` scene before it runs: :func:`plan_scene_case` (the kind's
``plan``) and :func:`check_scene_fits` (the memory guard the runner calls before building).

A scene is priced from the file's numbers (:func:`femkit.case.scene.systems.system_size`: nodes,
springs, the mesh it needs) by :func:`femkit.cost.plan_scene`; with ``measure`` its seconds per
step are timed on a first batch (:func:`femkit.case.cost.measure_step_seconds`).
"""

from __future__ import annotations

from ...cost import (SCENE_FREE_ITERATIONS, Plan, check_budget, contact_stage, machine_speed,
                     plan_mesh, plan_scene)
from ..contact import obstacle_facets
from ..cost import OVERRIDE, measure_step_seconds

__all__ = ["plan_scene_case", "check_scene_fits"]


def plan_scene_case(case, size, *, build=None, measure: bool = True) -> Plan:
    """The plan of a scene from ``case.spec`` (time grid, cadence, outputs) and ``size`` (a
    :class:`femkit.case.scene.systems.SystemSize`: nodes, springs, dim and the mesh it needs,
    counted from the file's numbers), before anything is allocated.

    With ``measure`` (and ``build() -> (system, integrator, ctx)``) the memory is checked first
    (a scene that cannot fit is refused before it is built:
    :class:`~femkit.errors.BudgetExceededError`, unless ``case.options.force``), then the
    system is built and its seconds per step timed on a first batch of steps (at most 20 steps
    or 1 s, :func:`measure_step_seconds`). ``size`` None (a system type that cannot count
    itself) needs ``build``: the plan is then made from the built system.
    """
    spec = case.spec
    method, implicit = spec.integrator.method, _implicit(spec.integrator)
    system = integrator = ctx = None
    if size is None:
        if build is None:
            return Plan("scene", f"{case.name}: {method}", {}, [],
                        assumptions=["no size model for this system type: the run is not costed"])
        system, integrator, ctx = build()
        nodes, springs, dim, mesh = system.n, system.n_springs, system.dim, None
    else:
        nodes, springs, dim, mesh = size.nodes, size.springs, size.dim, size.mesh
    common = dict(n_nodes=nodes, n_springs=springs, dim=dim, dt=spec.dt, t_end=spec.t_end,
                  every=spec.output.every, outputs=spec.output.files(), method=method,
                  implicit=implicit, name=case.name)
    plan = _with_contact(_with_mesh(plan_scene(**common), mesh), spec, nodes)
    if not measure or build is None:
        return plan
    if system is None:
        check_budget(plan, force=case.options.force, override=OVERRIDE)
        system, integrator, ctx = build()
    per_step = measure_step_seconds(system, integrator, spec.dt, ctx=ctx)
    speed = machine_speed(statistic="median") if getattr(spec, "contact", None) else 1.0
    return _with_contact(_with_mesh(plan_scene(**common, step_seconds=per_step), mesh), spec,
                         nodes, speed)


def _with_contact(plan: Plan, spec, nodes: float, speed: float = 1.0) -> Plan:
    """``plan`` with barrier contact's stage when the scene declares ``contact:`` (a surface of
    ~2 triangles per node, a sphere obstacle's 20 * 4^level; a Newton iteration of the
    contact-free step the ``simulate`` stage priced, :func:`femkit.cost.contact_stage`; ``speed``
    the machine's now, load included, when that step was measured)."""
    if getattr(spec, "contact", None) is None:
        return plan
    simulate = next(s for s in plan.stages if s.name == "simulate")
    step = simulate.seconds / max(spec.steps, 1)
    plan.stages.append(contact_stage(spec.steps, 2.0 * nodes + obstacle_facets(spec.contact),
                                     step / SCENE_FREE_ITERATIONS, SCENE_FREE_ITERATIONS, speed))
    plan.assumptions.append(
        f"contact: every step in contact, each a contact-free step's {SCENE_FREE_ITERATIONS:g} "
        "Newton iterations and more (femkit/cost/contact.py)"
        + (f"; contact's own work at this machine's speed now (x{speed:.2g})" if speed != 1.0
           else ""))
    return plan


def check_scene_fits(case, size) -> None:
    """The memory guard of a scene before its system is built (``force`` skips it): the model's
    peak from the file's numbers against the available memory."""
    if size is None or case.options.force:
        return
    check_budget(plan_scene_case(case, size, measure=False), override=OVERRIDE)


def _implicit(integrator_spec) -> bool:
    """Whether the integrator is implicit (the integrator object alone is built, no system)."""
    return bool(integrator_spec.build().implicit)


def _with_mesh(plan: Plan, mesh: dict | None) -> Plan:
    """``plan`` with the mesh stages of a mesh system in front (generation, reading)."""
    if mesh is not None:
        stages = plan_mesh(**mesh).stages
        plan.stages[:0] = stages
        plan.assumptions.append("nodes ~ triangles / 2, springs ~ 3 triangles / 2 (the mesh's edges)")
    return plan
