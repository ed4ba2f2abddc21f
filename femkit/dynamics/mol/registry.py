"""The registries of the method-of-lines integrators: :data:`HEAT_INTEGRATORS` (first order,
``M u' + K u = F(t)``) and :data:`WAVE_INTEGRATORS` (second order, ``M u'' + K u = F(t)``).

A scheme is a frozen dataclass whose fields are its options, registered with
:func:`register_heat` or :func:`register_wave` (the name written once, on the class, as
:func:`femkit.dynamics.integrators.registry.register` does for the mass-spring integrators);
its traits (``order``, ``explicit``, ``stability_bound``, ``embedded``) are class attributes,
so nothing keeps a table of names.

>>> from femkit.dynamics.mol import HEAT_INTEGRATORS, get_scheme
>>> get_scheme(HEAT_INTEGRATORS, "crank_nicolson").theta
0.5
>>> get_scheme(HEAT_INTEGRATORS, "crank_nicolson", thta=1.0)
Traceback (most recent call last):
...
femkit.errors.InputError: integrator 'crank_nicolson': unknown option 'thta' (did you mean 'theta'?); valid options: theta
"""

from __future__ import annotations

from ...errors import InputError
from ...registry import Registry
from ..integrators.registry import check_options

__all__ = ["HEAT_INTEGRATORS", "WAVE_INTEGRATORS", "register_heat", "register_wave", "get_scheme"]

#: First-order schemes (``problem: heat``).
HEAT_INTEGRATORS: Registry = Registry("heat integrator")
#: Second-order schemes (``problem: wave``).
WAVE_INTEGRATORS: Registry = Registry("wave integrator")


def _register(registry: Registry, name: str):
    def decorator(cls):
        cls.name = name
        return registry.register(name, cls)

    return decorator


def register_heat(name: str):
    """Class decorator: register a first-order scheme as ``name`` (sets ``cls.name``)."""
    return _register(HEAT_INTEGRATORS, name)


def register_wave(name: str):
    """Class decorator: register a second-order scheme as ``name`` (sets ``cls.name``)."""
    return _register(WAVE_INTEGRATORS, name)


def get_scheme(registry: Registry, name: str, **options):
    """The scheme registered as ``name`` in ``registry``, built with ``options``.

    Raises
    ------
    UnknownNameError
        Unknown name (the valid ones listed).
    InputError
        An unknown option or a bad value (the scheme's own check, ``validate``).
    """
    cls = registry.get(name)
    check_options(name, cls, options)
    try:
        scheme = cls(**options)
    except (TypeError, ValueError) as exc:
        raise InputError(f"integrator {name!r}: invalid options {sorted(options)}: {exc}") from None
    scheme.validate()
    return scheme
