"""Mass-spring dynamics: model (system, forces, topologies, Jacobians, stability) and integrators.

Names are resolved lazily on first access, so ``import femkit.dynamics`` costs nothing::

    >>> import femkit.dynamics as dyn
    >>> dyn.MassSpringSystem.__name__
    'MassSpringSystem'
"""

from __future__ import annotations

#: submodule -> the names it exports here (imported on first access, by plain relative imports)
_EXPORTS = {
    "system": ("MassSpringSystem", "elastic_system"),
    "forces": ("Gravity", "ViscousDamping", "RayleighDamping", "GroundContact", "SphereContact"),
    "topology": ("rope", "cloth_grid", "mesh_springs", "single_spring"),
    "stability": ("estimate_omega_max", "critical_dt"),
}

__all__ = sorted(name for names in _EXPORTS.values() for name in names)


def __getattr__(name: str):
    if name in _EXPORTS["system"]:
        from . import system as module
    elif name in _EXPORTS["forces"]:
        from . import forces as module
    elif name in _EXPORTS["topology"]:
        from . import topology as module
    elif name in _EXPORTS["stability"]:
        from . import stability as module
    else:
        raise AttributeError(f"module 'femkit.dynamics' has no attribute {name!r}")
    value = getattr(module, name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(list(globals()) + __all__)
