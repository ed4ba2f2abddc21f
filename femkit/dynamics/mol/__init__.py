"""Method-of-lines time stepping of linear systems from finite elements: the heat equation
``M u' + K u = F(t)`` and the wave equation ``M u'' + K u = F(t)`` with time-dependent
Dirichlet data (:class:`LinearSystem`), one module per scheme registered by name in
:data:`HEAT_INTEGRATORS` / :data:`WAVE_INTEGRATORS`, the critical step of the explicit ones
(:func:`critical_step`) and the drivers (:func:`march`, :func:`march_adaptive`).

The mass-spring integrators of :mod:`femkit.dynamics.integrators` step nonlinear second-order
systems of positions; these step the linear systems of a problem kind's mesh, keeping one
factor per matrix across the steps. No file I/O here.
"""

from .base import HeatScheme, MolState, WaveScheme
from .march import MarchResult, march, march_adaptive
from .registry import HEAT_INTEGRATORS, WAVE_INTEGRATORS, get_scheme
from .stability import critical_step, largest_eigenvalue
from .system import (DIRECT_LIMIT, IC0_LIMIT, KEPT_FACTOR_METHODS, LinearSystem, step_solver,
                     stiffness_ratio)
from . import (  # noqa: F401  (registration side effects)
    explicit_euler, theta, bdf2, newmark, central_difference, variational_symplectic,
    implicit_euler_wave,
)

__all__ = ["HEAT_INTEGRATORS", "WAVE_INTEGRATORS", "get_scheme", "HeatScheme", "WaveScheme",
           "MolState", "LinearSystem", "KEPT_FACTOR_METHODS", "DIRECT_LIMIT", "IC0_LIMIT", "step_solver",
           "stiffness_ratio",
           "critical_step",
           "largest_eigenvalue", "march", "march_adaptive", "MarchResult"]
