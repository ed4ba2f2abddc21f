"""The integrator registry: ``INTEGRATORS.get(name)(**options)`` builds an integrator.

>>> from femkit.dynamics.integrators import INTEGRATORS, get_integrator
>>> get_integrator("newmark", beta=0.25).order
2
>>> "rk4" in INTEGRATORS, INTEGRATORS.get("rk4").name
(True, 'rk4')
"""

from __future__ import annotations

from ...errors import InputError
from ...registry import Registry

INTEGRATORS: Registry = Registry("integrator")


def register(name: str):
    """Class decorator: register an integrator class as ``name`` and set its ``name`` attribute
    (the name is written once, here)."""

    def decorator(cls):
        cls.name = name
        return INTEGRATORS.register(name, cls)

    return decorator


def get_integrator(name: str, **options):
    """Build the integrator registered as ``name`` with ``options`` (its dataclass fields).

    Raises
    ------
    UnknownNameError
        Unknown integrator name (the message lists the valid ones).
    InputError
        An option the integrator does not have, or an invalid option value.
    """
    cls = INTEGRATORS.get(name)
    try:
        return cls(**options)
    except TypeError as exc:
        raise InputError(f"integrator {name!r}: invalid options {sorted(options)}: {exc}") from None
