"""The cost of a ``stability`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage
from ..cost import runs_plan

__all__ = ["plan"]


def plan(study) -> Plan:
    """The plan of a ``stability`` study: each stress case priced by its type's ``price``
    (:data:`femkit.study.stability.cases.STRESS_CASES`), plus the warm-up."""
    from .cases import STRESS_CASES
    from .run import load_cases

    quick_n = 16 if study.quick else 64
    stages, runs = [], 0
    for case in load_cases(study):
        price = STRESS_CASES.get(case["type"]).price
        seconds, n = price(case, study, quick_n) if price is not None else (0.0, 0)
        runs += n
        stages.append(Stage(case["name"], seconds, 0.0, detail=f"{case['type']}, {n} run(s)"))
    return runs_plan(study, stages, runs, [
        "Poisson cases: the cost model's assembly, setup and solve on each case's mesh at the "
        "iteration counts of well-conditioned problems (ill-conditioned ones iterate longer); "
        "dynamics cases: the scene model's seconds per step"])
