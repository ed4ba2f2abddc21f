"""Mass-spring dynamics: model (system, forces, topologies, Jacobians, stability) and integrators.

Names are resolved lazily on first access, so ``import femkit.dynamics`` costs nothing::

    >>> import femkit.dynamics as dyn
    >>> dyn.MassSpringSystem.__name__
    'MassSpringSystem'
"""

from __future__ import annotations

import importlib

_EXPORTS = {
    "MassSpringSystem": "femkit.dynamics.system",
    "Gravity": "femkit.dynamics.forces",
    "ViscousDamping": "femkit.dynamics.forces",
    "RayleighDamping": "femkit.dynamics.forces",
    "GroundContact": "femkit.dynamics.forces",
    "SphereContact": "femkit.dynamics.forces",
    "rope": "femkit.dynamics.topology",
    "cloth_grid": "femkit.dynamics.topology",
    "mesh_springs": "femkit.dynamics.topology",
    "single_spring": "femkit.dynamics.topology",
    "estimate_omega_max": "femkit.dynamics.stability",
    "critical_dt": "femkit.dynamics.stability",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    try:
        module = _EXPORTS[name]
    except KeyError:
        raise AttributeError(f"module 'femkit.dynamics' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(list(globals()) + __all__)
