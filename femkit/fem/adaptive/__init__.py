"""The adaptive loop solve -> estimate -> mark -> refine (:mod:`femkit.fem.adaptive.loop`).

A folder of its own because it sits above :mod:`femkit.fem.estimators` (which builds on the
assembly modules of :mod:`femkit.fem`): no module of ``femkit/fem/`` itself imports it.
"""

from .loop import (REFINEMENTS, AdaptiveResult, LevelRecord, adaptive_solve, check_settings,
                   poisson_solver, problem_solver)

__all__ = ["REFINEMENTS", "AdaptiveResult", "LevelRecord", "adaptive_solve", "check_settings",
           "poisson_solver", "problem_solver"]
