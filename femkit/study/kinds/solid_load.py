"""``kind: solid_load``: a cantilever under a growing tip load, one curve per material.

Everything of the kind is in :mod:`femkit.study.solid_load` (schema, check, sweep, report,
summary); this module registers it. No cost model (the plan counts runs).
"""

from __future__ import annotations

from ...kinds import Kind, register_kind


def _schema() -> dict:
    from ..solid_load import solid_load_schema

    return solid_load_schema()


def _check(study) -> None:
    from ..solid_load import check_solid_load

    check_solid_load(study)


def _run(study, progress_enabled=None) -> dict:
    from ..solid_load import run_solid_load

    return run_solid_load(study, progress_enabled=progress_enabled)


def _plan(study, **kwargs):
    from ..cost import plan_solid_load_study

    return plan_solid_load_study(study)


def _report(*args) -> None:
    from ..solid_load import build_solid_load_report

    build_solid_load_report(*args)


def _summary(result) -> list[str]:
    from ..solid_load import solid_load_summary

    return solid_load_summary(result)


KIND = register_kind(Kind("solid_load", "kind", _schema, _check, _run, plan=_plan,
                          report=_report, summary=_summary))
