"""A-posteriori error estimators of P1 solutions of ``-div(kappa grad u) = f``.

Two estimators of the energy-norm error ``|||u - u_h||| = (int kappa |grad(u - u_h)|^2)^(1/2)``,
each giving one indicator ``eta_T`` per element and the global ``sqrt(sum eta_T^2)``:

- ``residual``: the explicit residual estimator (Babuška & Rheinboldt 1978; Verfürth 1996, 2013),
  kappa-weighted after Bernardi & Verfürth (2000) so a high coefficient contrast does not spoil it
  (:mod:`.residual`);
- ``zz``: gradient recovery by area-weighted nodal averaging (Zienkiewicz & Zhu 1987), recovered
  region by region so coefficient jumps are not smeared (:mod:`.recovery`).

:func:`estimate` applies one, by name, to a :class:`~femkit.fem.PoissonProblem` and its solution.
"""

from .base import ESTIMATORS, ErrorEstimate
from .recovery import zz_estimator
from .residual import residual_estimator
from .apply import estimate, problem_data

__all__ = ["ESTIMATORS", "ErrorEstimate", "estimate", "problem_data", "residual_estimator",
           "zz_estimator"]
