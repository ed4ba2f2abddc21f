"""``kind: cloth_work_precision``: which implicit cloth method buys the most accuracy per millisecond.

Everything of the kind is in :mod:`femkit.study.cloth` (schema, check, sweep, report, summary);
this module registers it. Cost plan :func:`femkit.study.cost.plan_cloth_study`.
"""

from __future__ import annotations

from ...kinds import Kind, register_kind


def _schema() -> dict:
    from ..cloth import cloth_schema

    return cloth_schema()


def _check(study) -> None:
    from ..cloth import check_cloth_study

    check_cloth_study(study)


def _run(study, progress_enabled=None) -> dict:
    from ..cloth import run_cloth_study

    return run_cloth_study(study, progress_enabled=progress_enabled)


def _plan(study, **kwargs):
    from ..cost import plan_cloth_study

    return plan_cloth_study(study)


def _report(*args) -> None:
    from ..cloth import build_cloth_report

    build_cloth_report(*args)


def _summary(result) -> list[str]:
    from ..cloth import cloth_summary

    return cloth_summary(result)


KIND = register_kind(Kind("cloth_work_precision", "kind", _schema, _check, _run,
                          plan=_plan, report=_report, summary=_summary, default_solver="direct"))
