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
    check_options(name, cls, options)
    try:
        return cls(**options)
    except (TypeError, ValueError) as exc:
        raise InputError(f"integrator {name!r}: invalid options {sorted(options)}: {exc}") from None


def check_options(name: str, cls, options: dict) -> None:
    """Option names against the integrator's dataclass fields (the valid ones listed, the nearest
    suggested) and option values against the fields' types, before the class sees them."""
    import dataclasses
    import difflib
    import typing

    if not dataclasses.is_dataclass(cls):
        return
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init and not f.name.startswith("_")}
    for key in options:
        if key not in fields:
            near = difflib.get_close_matches(str(key), list(fields), n=1)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            raise InputError(f"integrator {name!r}: unknown option {key!r}{hint}; valid options: "
                             f"{', '.join(sorted(fields)) or '(none)'}")
    try:
        hints = typing.get_type_hints(cls)
    except Exception:  # an annotation that does not resolve: leave the value check to the class
        return
    accepts = {float: (int, float), int: (int,), bool: (bool,), str: (str,)}
    words = {float: "a number", int: "an integer", bool: "true or false", str: "a string"}
    for key, value in options.items():
        want = typing.get_args(hints.get(key)) or (hints.get(key),)  # `float | None` -> both
        if value is None and type(None) in want:
            continue
        kinds = [t for t in want if t in accepts]
        if not kinds or len(kinds) < len([t for t in want if t is not type(None)]):
            continue  # a type this check does not know: the class checks it
        if not any(isinstance(value, accepts[t]) and (t is bool or not isinstance(value, bool))
                   for t in kinds):
            allowed = " or ".join(words[t] for t in kinds) + (" or null" if type(None) in want else "")
            raise InputError(f"integrator {name!r}: option {key!r} must be {allowed}, got {value!r}")
