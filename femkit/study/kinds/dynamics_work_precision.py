"""``kind: dynamics_work_precision``: error against cost of integrators on a small scene.

Sweep :func:`femkit.study.dynamics.run_dynamics_study`, report
:func:`femkit.study.report_dynamics.build_dynamics_report`; schema
:data:`femkit.study.schema.DYNAMICS`. Cost plan :func:`femkit.study.cost.plan_dynamics_study`.
"""

from __future__ import annotations

from ...kinds import Kind, register_kind
from ...errors import CaseFileError
from ..schema import DYNAMICS
from ..spec import DynamicsStudySpec
from ..summary import fit_lines


def _check(study) -> None:
    d = study.data
    for key in ("scene", "integrators", "dt"):
        if key not in d:
            raise CaseFileError(f"(top level): missing required key {key!r}")
    dt = d["dt"]
    if "values" not in dt and not ("k_min" in dt and "k_max" in dt and dt["k_max"] > dt["k_min"]):
        raise CaseFileError("dt: give 'values' or 'k_min' < 'k_max' (dt = 2^-k)")
    study.spec = DynamicsStudySpec.from_data(d)


def _run(study, progress_enabled=None) -> dict:
    from ..dynamics import run_dynamics_study

    return run_dynamics_study(study, progress_enabled=progress_enabled)


def _plan(study, **kwargs):
    from ..cost import plan_dynamics_study

    return plan_dynamics_study(study)


def _report(*args) -> None:
    from ..report_dynamics import build_dynamics_report

    build_dynamics_report(*args)


KIND = register_kind(Kind("dynamics_work_precision", "kind", DYNAMICS, _check, _run,
                          plan=_plan, report=_report, summary=fit_lines))
