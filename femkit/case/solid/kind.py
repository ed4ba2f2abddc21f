"""``problem: solid``: an elastic-solid case file, registered as a :class:`~femkit.kinds.Kind`.

Schema :func:`femkit.case.solid.schema.solid_schema` (enums from the material, geometry and
integrator registries); load-time checks and the spec :func:`femkit.case.solid.run.prepare_solid`;
the run :func:`femkit.case.solid.run.run_solid`; the plan
:func:`femkit.case.solid.cost.plan_solid_case`. Library modules are imported on first use.
"""

from __future__ import annotations

from ...kinds import Kind, register_kind


def _schema() -> dict:
    from .schema import solid_schema

    return solid_schema()


def _prepare(case) -> None:
    from .run import prepare_solid

    prepare_solid(case)


def _run(case, **kwargs):
    from .run import run_solid

    return run_solid(case, **kwargs)


def _plan(case, **kwargs):
    from .cost import plan_solid_case

    return plan_solid_case(case, **kwargs)


def _view(run, **options):
    from .view import solid_view

    return solid_view(run, **options)


KIND = register_kind(Kind("solid", "problem", _schema, _prepare, _run, _plan,
                          default_solver="direct", view=_view))
