"""Time integrators for mass-spring systems, one file per method, all in :data:`INTEGRATORS`.

>>> from femkit.dynamics.integrators import INTEGRATORS
>>> INTEGRATORS.names()[:3]
['central_difference', 'explicit_euler', 'fast_mass_spring']
"""

import importlib
import pkgutil

from .base import Integrator, StepContext, StepperState
from .registry import INTEGRATORS, get_integrator

# an integrator's module registers it when imported (``@register``), so every module of this
# package is imported here: adding an integrator is adding its file
for _m in pkgutil.iter_modules(__path__):
    importlib.import_module(f"{__name__}.{_m.name}")

__all__ = ["INTEGRATORS", "get_integrator", "Integrator", "StepContext", "StepperState"]
