"""``kind: poisson_convergence``: error and cost of a Poisson case over a sequence of meshes.

Sweep :func:`femkit.study.poisson.run_poisson_study`, report
:func:`femkit.study.report_poisson.build_poisson_report`, cost plan
:func:`femkit.study.cost.plan_poisson_study`; schema :data:`femkit.study.schema.POISSON`.
"""

from __future__ import annotations

from ...kinds import Kind, register_kind
from ...errors import CaseFileError
from ..checks import check_base_case, check_nested, check_problem_source
from ..schema import POISSON
from ..spec import PoissonStudySpec
from ..summary import r2_text


def _check(study) -> None:
    check_problem_source(study, "poisson_convergence")
    lv = study.data.get("levels") or {}
    if "h" not in lv and not ("h0" in lv and "count" in lv):
        raise CaseFileError("levels: give either 'h' (a list of mesh sizes) or 'h0' and 'count' "
                            "(uniform refinements of one mesh)")
    study.spec = PoissonStudySpec.from_data(study.data)
    check_base_case(study)
    from ..problem import study_problem

    study_problem(study)  # the problem's keys, names and expressions are checked now
    check_nested(study, "h" in lv, "levels: {h: [...]} gives independent gmsh meshes, not "
                 "nested ones; use levels: {h0, count} (uniform refinements)")


def _run(study, progress_enabled=None) -> dict:
    from ..poisson import run_poisson_study

    return run_poisson_study(study, progress_enabled=progress_enabled)


def _plan(study, **kwargs):
    from ..cost import plan_poisson_study

    return plan_poisson_study(study)


def _report(*args) -> None:
    from ..report_poisson import build_poisson_report

    build_poisson_report(*args)


def _summary(result) -> list[str]:
    from ..report_poisson import grouped_rate_rows

    # one line per group of solvers with the same fit, like the report
    return [f"rate {who} / {rule} / {norm}: {slope:.3f} ({r2_text(r2)})"
            for who, rule, norm, slope, _, r2, *_ in grouped_rate_rows(result.fits)]


KIND = register_kind(Kind("poisson_convergence", "kind", POISSON, _check, _run, _plan,
                          _report, _summary))
