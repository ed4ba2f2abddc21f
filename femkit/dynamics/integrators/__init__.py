"""Time integrators for mass-spring systems, one file per method, all in :data:`INTEGRATORS`.

>>> from femkit.dynamics.integrators import INTEGRATORS
>>> INTEGRATORS.names()[:3]
['central_difference', 'explicit_euler', 'fast_mass_spring']
"""

from .base import Integrator, StepContext, StepperState
from .registry import INTEGRATORS, get_integrator
from . import (  # noqa: F401  (registration side effects)
    explicit_euler,
    symplectic_euler,
    heun,
    midpoint,
    rk4,
    verlet,
    velocity_verlet,
    leapfrog,
    central_difference,
    implicit_euler,
    newton,
    newmark,
    variational_symplectic,
    fast_mass_spring,
    projective,
)

__all__ = ["INTEGRATORS", "get_integrator", "Integrator", "StepContext", "StepperState"]
