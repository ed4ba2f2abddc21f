"""The cost of a case or scene file before it runs: its plan, the budget check, the stop flag.

:func:`plan_case` translates a loaded case into a :class:`femkit.cost.Plan` through its
kind (``KINDS[...].plan``); :func:`check_case` checks it against the case's
``limits:``, the command line's ``--max-memory`` and the available memory, refusing with
:class:`~femkit.errors.BudgetExceededError` (exit code 2, one line) unless forced. Run options
travel in ``case.run_options``: ``limits`` (:class:`femkit.cost.Limits`, from the file), ``force``
(skip every budget, also the library's own memory checks), ``stop`` (a
:class:`femkit.interrupt.StopFlag` the runners check between steps and iterations) and
``plan`` (set by :func:`check_case`: a Poisson run predicted to last 30 s or more prints a
line on stderr after each stage with the elapsed and the predicted remaining time).
"""

from __future__ import annotations

import sys

from ..cost import Limits, Plan, check_budget, plan_poisson, plan_scene
from .load import Case

__all__ = ["plan_case", "check_case", "plan_poisson_case", "plan_scene_case"]

OVERRIDE = "--force"


def plan_poisson_case(case: Case, *, measure: bool = True) -> Plan:
    """The plan of a Poisson case; with ``measure`` its seconds are scaled by this machine's
    speed now (:func:`femkit.cost.machine_speed`, ~0.25 s of probing)."""
    from ..cost import machine_speed, msh_triangle_count

    d = case.data
    spec = d["mesh"]
    out = d["output"]
    outputs = tuple(k for k, on in (("vtu", out["vtu"]), ("xdmf", out["xdmf"]), ("png", out["plot"])) if on)
    common = dict(refine=spec.get("refine", 0), method=case.solver.method,
                  speed=machine_speed() if measure else 1.0,
                  preconditioner=case.solver.preconditioner, rtol=case.solver.rtol,
                  outputs=outputs, errors="exact.u" in case.functions)
    if "file" in spec:
        triangles, how = msh_triangle_count(spec["file"])
        plan = plan_poisson(triangles=triangles, **common)
        plan.assumptions.insert(0, f"{triangles:,} triangles in {spec['file']} (from {how})")
    else:
        plan = plan_poisson(geometry=spec["geometry"], h=spec["h"], params=spec.get("params"), **common)
    plan.title = f"{case.name}: {plan.title}"
    if d.get("adaptive"):
        plan.assumptions.append("adaptive refinement: only the first level is costed; the "
                                "adaptive budgets (max_dofs, max_time, max_levels) bound the rest")
    return plan


def plan_scene_case(case: Case, *, measure: bool = True) -> Plan:
    """The plan of a scene: the system is built (cheap) and, with ``measure``, the seconds per
    step are timed on a first batch of steps (at most 20 steps or 1 s)."""
    from ..cost import measure_step_seconds
    from .scene.run import build_context, build_integrator, build_system, output_every

    d = case.data
    system, _ = build_system(case)
    integrator = build_integrator(case)
    per_step = None
    if measure:
        per_step = measure_step_seconds(system, integrator, d["dt"], ctx=build_context(case))
    out = d["output"]
    outputs = tuple(k for k in ("vtu", "xdmf", "energy_csv", "png", "gif") if out[k])
    plan = plan_scene(n_nodes=system.n, n_springs=system.n_springs, dim=system.dim, dt=d["dt"],
                      t_end=d["t_end"], every=output_every(case), outputs=outputs,
                      method=integrator.name, implicit=integrator.implicit, step_seconds=per_step,
                      name=case.name)
    return plan


def plan_case(case: Case, *, measure: bool = True) -> Plan:
    """The plan of any case, through its kind (``KINDS[case.problem].plan``)."""
    from .kinds import KINDS

    kind = KINDS.get(case.problem, "problem")
    if kind.plan is None:  # a kind without a cost model runs unchecked, and the plan says so
        from ..cost import load_constants

        return Plan("case", f"{case.name}: {case.problem}", {}, [],
                    load_constants()["bytes"]["baseline"],
                    assumptions=[f"no cost model for problem {case.problem!r}: the run is unchecked"])
    return kind.plan(case, measure=measure)


def check_case(case: Case, *, max_memory: float | None = None, force: bool = False,
               echo=None) -> Plan:
    """Plan ``case`` and refuse it when it exceeds a budget (before anything runs).

    Limits: the file's ``limits:``, ``max_memory`` (bytes, ``--max-memory``) and the available
    memory. Steps and memory are checked on the model alone (immediately, however large the
    run); a time limit first measures: the machine's speed (Poisson) or a batch of steps (scenes). With ``force`` the
    violations are printed as warnings on stderr and the run goes on (also past the
    library's own memory checks: ``case.run_options["force"]``).

    Raises
    ------
    BudgetExceededError
        A limit is exceeded and ``force`` is false.
    """
    limits = case.run_options.get("limits") or Limits()
    if max_memory is not None:
        limits = limits.merged(Limits(memory=max_memory))
    case.run_options["force"] = bool(force)
    say = echo or (lambda line: print(line, file=sys.stderr))
    untimed = Limits(limits.memory, None, limits.steps, limits.output, limits.check_available)
    plan = plan_case(case, measure=False)
    warnings = check_budget(plan, untimed, force=force, override=OVERRIDE)
    if limits.time is not None:
        plan = plan_case(case, measure=True)
        warnings += check_budget(plan, Limits(time=limits.time, check_available=False),
                                 force=force, override=OVERRIDE)
    for w in warnings:
        say(f"femkit: warning: {w.replace(f' (or {OVERRIDE} to run anyway)', '')} ({OVERRIDE} given)")
    case.run_options["plan"] = plan  # long Poisson runs report each stage against it
    return plan
