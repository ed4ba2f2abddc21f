"""``kind: adaptive``: adaptive against uniform refinement of one Poisson case.

Sweep :func:`femkit.study.adaptive.run_adaptive_study`, report
:func:`femkit.study.adaptive.build_adaptive_report`; schema :data:`femkit.study.schema.ADAPTIVE`.
"""

from __future__ import annotations

from ...kinds import Kind, register_kind
from ...errors import CaseFileError
from ..checks import check_base_case, check_nested, check_problem_source
from ..schema import ADAPTIVE
from ..spec import AdaptiveStudySpec


def _check(study) -> None:
    from ...case.names import lookup
    from ...fem.adaptive import check_settings
    from ...fem.estimators import ESTIMATORS

    d = study.data
    check_problem_source(study, "adaptive")
    if "max_dofs" not in d:
        raise CaseFileError("(top level): missing required key 'max_dofs' (the budget of both refinements)")
    for i, name in enumerate(d["estimators"]):
        lookup(ESTIMATORS, name, f"estimators[{i}]")
    check_settings(theta=d["theta"], target=d.get("target"), max_dofs=d["max_dofs"],
                   max_time=d.get("max_time"), max_levels=d["max_levels"])
    study.spec = AdaptiveStudySpec.from_data(d)
    check_base_case(study)
    from ..problem import study_problem

    study_problem(study, need_exact=False)
    check_nested(study, True, "adaptive refinement makes graded meshes, not uniformly refined "
                 "nested ones")


def _run(study, progress_enabled=None) -> dict:
    from ..adaptive import run_adaptive_study

    return run_adaptive_study(study, progress_enabled=progress_enabled)


def _plan(study, **kwargs):
    from ..cost import plan_adaptive_study

    return plan_adaptive_study(study)


def _report(*args) -> None:
    from ..adaptive import build_adaptive_report

    build_adaptive_report(*args)


def _summary(result) -> list[str]:
    from ..adaptive import adaptive_summary

    return adaptive_summary(result)


KIND = register_kind(Kind("adaptive", "kind", ADAPTIVE, _check, _run, plan=_plan, report=_report,
                          summary=_summary))
