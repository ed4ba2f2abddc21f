"""``problem: poisson``: a P1 Poisson case file, registered as a :class:`~femkit.kinds.Kind`.

Schema :data:`femkit.case.poisson.schema.POISSON_SCHEMA`; load-time checks
:func:`femkit.case.poisson.run.prepare_poisson`; the run :func:`femkit.case.poisson.run.run_poisson`;
the cost plan :func:`femkit.case.poisson.cost.plan_poisson_case`. The pipeline modules are imported on
first use, so discovering this kind imports nothing heavy.
"""

from __future__ import annotations

from ...kinds import Kind, register_kind


def _schema() -> dict:
    from .schema import POISSON_SCHEMA

    return POISSON_SCHEMA


def _prepare(case) -> None:
    from .run import prepare_poisson

    prepare_poisson(case)


def _run(case, **kwargs):
    from .run import run_poisson

    return run_poisson(case, **kwargs)


def _plan(case, **kwargs):
    from .cost import plan_poisson_case

    return plan_poisson_case(case, **kwargs)


def _view(run, **options):
    from .view import poisson_view

    return poisson_view(run, **options)


KIND = register_kind(Kind("poisson", "problem", _schema, _prepare, _run, _plan,
                          default_solver="pcg", view=_view))
