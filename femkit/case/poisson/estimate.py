"""Error estimates of a Poisson case: the ``error_estimate`` / ``effectivity`` / ``adaptive`` facts
of result.json, and the adaptive loop run through the one Poisson pipeline.

The estimator is the case's ``estimator`` (default ``residual``; :mod:`femkit.fem.estimators`);
``effectivity`` = estimate / true energy-norm error needs ``exact.grad``. With ``adaptive:`` the
case is solved by :func:`femkit.fem.adaptive.adaptive_solve`, each level built by
:func:`~femkit.case.poisson.run.poisson_problem` and solved with the case's solver from the
previous level's interpolated solution.
"""

from __future__ import annotations

import numpy as np

__all__ = ["estimate_facts", "solve_adaptive", "adaptive_facts"]


def estimate_facts(case, problem, u: np.ndarray, grad_exact=None, est=None):
    """``(error_estimate dict, effectivity or None, ErrorEstimate)`` of the solution ``u``.

    ``error_estimate``: ``estimator``, ``energy`` (the global estimate of
    ``(int kappa |grad(u - u_h)|^2)^(1/2)``), ``per_region`` (by cell group) and, with an exact
    gradient, ``true_energy_error``.
    """
    from ...fem.estimators import estimate
    from ...fem.norms import energy_error

    if est is None:
        est = estimate(problem, u, case.spec.estimator)
    facts = {"estimator": est.estimator, "energy": est.energy, "per_region": est.per_region(problem.mesh)}
    eff = None
    if grad_exact is not None:
        if problem.element.name == "P1":
            err = energy_error(problem.mesh, u, grad_exact, problem.kappa)
        else:
            from ...fem.lagrange import element_energy_error

            err = element_energy_error(problem.mesh, u, grad_exact, problem.kappa, element=problem.element)
        facts["true_energy_error"] = err
        eff = est.effectivity(err) if err > 0 else None
    return facts, eff, est


def solve_adaptive(case, mesh, *, echo=None):
    """Run the case's ``adaptive:`` loop from ``mesh``; an :class:`~femkit.fem.adaptive.AdaptiveResult`."""
    from ...fem.adaptive import adaptive_solve, problem_solver
    from .problem import exact_gradient, poisson_problem

    a = case.spec.adaptive
    solve_on = problem_solver(lambda m: poisson_problem(case, m), case.solver.solve, case.solver.method)
    return adaptive_solve(solve_on, mesh, theta=a["theta"], target=a.get("target"),
                          max_dofs=a.get("max_dofs"), max_time=a.get("max_time"),
                          max_levels=a["max_levels"], estimator=case.spec.estimator,
                          grad_exact=exact_gradient(case))


def adaptive_facts(run) -> dict:
    """result.json's ``adaptive``: settings, ``target_met``, ``stop_reason`` and one record per level."""
    return {**{k: v for k, v in run.settings.items() if k not in ("estimator",)},
            "target_met": run.target_met, "stop_reason": run.stop_reason,
            "total_time": run.total_time, "levels": [lv.as_dict() for lv in run.levels]}
