"""``problem: heat``: the heat equation ``rho_c u_t - div(kappa grad u) = f(x, t)`` on femkit's
meshes, registered as a :class:`~femkit.kinds.Kind`.

Schema :func:`femkit.case.heat.schema.heat_schema`; load-time checks and the spec
:func:`femkit.case.heat.run.prepare_heat`; the run :func:`femkit.case.heat.run.run_heat`; the
plan :func:`femkit.case.heat.cost.plan_heat_case`. The default linear solver is ``direct``: each
step of a fixed ``dt`` reuses one factor of ``M + theta dt K`` (a pair of triangular solves per
step, docs/heat_wave.md says why).
"""

from __future__ import annotations

from ...kinds import Kind, register_kind


def _schema() -> dict:
    from .schema import heat_schema

    return heat_schema()


def _prepare(case) -> None:
    from .run import prepare_heat

    prepare_heat(case)


def _run(case, **kwargs):
    from .run import run_heat

    return run_heat(case, **kwargs)


def _plan(case, **kwargs):
    from .cost import plan_heat_case

    return plan_heat_case(case, **kwargs)


KIND = register_kind(Kind("heat", "problem", _schema, _prepare, _run, _plan,
                          default_solver="direct"))
