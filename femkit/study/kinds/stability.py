"""``kind: stability``: the stress suite, one verdict row per (case, parameter, method).

Sweep :func:`femkit.study.stability.run_stability_study` over the stress-case types of
:data:`femkit.study.stability.STRESS_CASES`, report
:func:`femkit.study.report_stability.build_stability_report`; schema
:func:`femkit.study.stability.stability_schema`. Cost plan :func:`femkit.study.cost.plan_stability_study`.
"""

from __future__ import annotations

from ...kinds import Kind, register_kind
from ...errors import CaseFileError
from ..spec import StabilityStudySpec
from ..summary import fit_lines


def _schema() -> dict:
    from ..stability import stability_schema

    return stability_schema()


def _check(study) -> None:
    for i, c in enumerate(study.data["cases"]):
        if isinstance(c, str):
            p = study.resolve(c)
            if not p.is_file():
                raise CaseFileError(f"cases[{i}]: stress case file not found: {p}")
            study.files.append(p)
    study.spec = StabilityStudySpec.from_data(study.data)


def _run(study, progress_enabled=None) -> dict:
    from ..stability import run_stability_study

    return run_stability_study(study, progress_enabled=progress_enabled)


def _plan(study, **kwargs):
    from ..cost import plan_stability_study

    return plan_stability_study(study)


def _report(*args) -> None:
    from ..report_stability import build_stability_report

    build_stability_report(*args)


KIND = register_kind(Kind("stability", "kind", _schema, _check, _run,
                          plan=_plan, report=_report, summary=fit_lines))
