"""``kind: springs_vs_elements``: mass-spring layouts against finite elements and projective
dynamics on the same gmsh meshes (a hanging beam, a falling disk).

Everything of the kind is in :mod:`femkit.study.springs_elements` (schema, check, sweep,
summary), :mod:`femkit.study.report_springs` (figures and report) and
:func:`femkit.study.cost.plan_springs_study` (the plan); this module registers it.
"""

from __future__ import annotations

from ...kinds import Kind, register_kind


def _schema() -> dict:
    from ..springs_elements import springs_schema

    return springs_schema()


def _check(study) -> None:
    from ..springs_elements import check_springs

    check_springs(study)


def _run(study, progress_enabled=None) -> dict:
    from ..springs_elements import run_springs

    return run_springs(study, progress_enabled=progress_enabled)


def _plan(study, **kwargs):
    from ..cost import plan_springs_study

    return plan_springs_study(study)


def _report(*args) -> None:
    from ..report_springs import build_springs_report

    build_springs_report(*args)


def _summary(result) -> list[str]:
    from ..springs_elements import springs_summary

    return springs_summary(result)


KIND = register_kind(Kind("springs_vs_elements", "kind", _schema, _check, _run, plan=_plan,
                          report=_report, summary=_summary))
