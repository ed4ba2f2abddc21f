"""What ``femkit list`` prints: every name a case or study file may use, read from the registries.

Each group is one registry (:data:`GROUPS`: group name -> a function returning that registry),
so a geometry, solver, force or kind registered anywhere (a plugin included) is listed with no
table to keep in step. A name's description is the first line of its docstring (a class with
only the generated dataclass signature falls back to its module's docstring), or what the
record itself says (a geometry's dimension, parameters and tags).

>>> rows = entries("preconditioners")
>>> ("none" in dict(rows), all(isinstance(d, str) for _, d in rows))
(True, True)
"""

from __future__ import annotations

import re
import sys
from typing import Callable

__all__ = ["GROUPS", "entries", "describe", "render"]


def _geometries():
    from .mesh.geometries import GEOMETRIES

    return GEOMETRIES


def _solvers():
    from .solvers.registry import SOLVERS

    return SOLVERS


def _preconditioners():
    from .solvers.registry import PRECONDITIONERS

    return PRECONDITIONERS


def _backends():
    from .solvers.registry import BACKENDS

    return BACKENDS


def _integrators():
    from .dynamics.integrators.registry import INTEGRATORS

    return INTEGRATORS


def _heat_integrators():
    from .dynamics.mol import HEAT_INTEGRATORS

    return HEAT_INTEGRATORS


def _wave_integrators():
    from .dynamics.mol import WAVE_INTEGRATORS

    return WAVE_INTEGRATORS


def _forces():
    from .case.scene.forces import FORCES

    return FORCES


def _systems():
    from .case.scene.systems import SYSTEMS

    return SYSTEMS


def _materials():
    from .solids.materials.builtin_materials import MATERIALS

    return MATERIALS


class _Family:
    """One family of :data:`femkit.kinds.KINDS` seen as a registry (``names``/``get``)."""

    def __init__(self, key: str):
        self.key = key

    @staticmethod
    def _kinds():
        from . import case, study  # noqa: F401  each hands KINDS the finder of its own kinds
        from .kinds import KINDS

        return KINDS

    def names(self) -> list[str]:
        return self._kinds().names(self.key)

    def get(self, name: str):
        return self._kinds().get(name, self.key)


#: group name -> (what it is, function returning its registry). Order = ``femkit list`` order.
GROUPS: dict[str, tuple[str, Callable]] = {
    "geometries": ("mesh.geometry / system.geometry of a case", _geometries),
    "solvers": ("solver.method", _solvers),
    "preconditioners": ("solver.preconditioner", _preconditioners),
    "backends": ("solver.backend (--backend)", _backends),
    "integrators": ("integrator.method of a scene", _integrators),
    "heat_integrators": ("integrator of a heat case (problem: heat)", _heat_integrators),
    "wave_integrators": ("integrator of a wave case (problem: wave)", _wave_integrators),
    "forces": ("forces of a scene", _forces),
    "systems": ("system.type of a scene", _systems),
    "materials": ("material of an elastic solid", _materials),
    "problems": ("problem: of a case file (femkit solve)", lambda: _Family("problem")),
    "studies": ("kind: of a study file (femkit study)", lambda: _Family("kind")),
}


def _first_line(text: str | None) -> str:
    """The first sentence of a docstring's first paragraph, without reST markup.

    A sentence ends at ``.`` or ``:`` before a capital, but not after an abbreviation or an
    initial (``St.``, ``B.``).

    >>> _first_line("``kind: x``: does y with :func:`~a.b` (see\\n  there). More.\\n\\nBody")
    'does y with b (see there).'
    >>> _first_line("St. Venant-Kirchhoff after B. de Saint-Venant (1844). More.")
    'St. Venant-Kirchhoff after B. de Saint-Venant (1844).'
    """
    para = " ".join((text or "").strip().split("\n\n")[0].split())
    para = re.sub(r"^``[^`]*``: ", "", para)  # the ``kind: name``: heading of a kind's module
    para = re.sub(r":\w+:`~?(?:[\w.]*\.)?([^`]+)`", r"\1", para).replace("``", "")
    return _SENTENCE_END.split(para)[0].split(", registered as")[0]


#: a sentence end: ``.`` or ``:``, then a capital, not after ``St.``-like abbreviations or initials
_SENTENCE_END = re.compile(r"(?<=[.:])(?<!\b[A-Z][a-z]\.)(?<!\b[A-Z]\.)\s+(?=[A-Z])")


def describe(obj) -> str:
    """One line saying what a registered ``obj`` is (see the module docstring)."""
    import inspect

    from .mesh.geometries import Geometry

    if isinstance(obj, Geometry):
        params = ", ".join(obj.parameters) or "none"
        return f"{obj.dim}D; parameters: {params}; tags: {', '.join(obj.boundary_tags + obj.cell_tags)}"
    run = getattr(obj, "run", None)
    if callable(run) and hasattr(obj, "key"):  # a file kind (whatever its schema): its module
        return _first_line(sys.modules[run.__module__].__doc__)
    schema = getattr(obj, "schema", None)
    if isinstance(schema, dict) and "properties" in schema:  # forces, system types
        keys = [k for k in schema["properties"] if k != "type"]
        return "keys: " + ", ".join(keys) if keys else "no keys"
    text = _first_line(getattr(obj, "__doc__", None))
    if inspect.isclass(obj) and text.startswith(obj.__name__ + "("):  # generated signature
        text = _first_line(sys.modules[obj.__module__].__doc__)
    return text


def _group(group: str):
    from .errors import UnknownNameError

    if group not in GROUPS:
        raise UnknownNameError("group", group, GROUPS)
    return GROUPS[group][1]()


def entries(group: str) -> list[tuple[str, str]]:
    """``(name, description)`` of every entry of ``group`` (a key of :data:`GROUPS`), sorted."""
    registry = _group(group)
    return [(name, describe(registry.get(name))) for name in registry.names()]


def render(groups=None) -> str:
    """The text ``femkit list [GROUP ...]`` prints."""
    from .plugins import load_plugins

    load_plugins()  # a plugin's entries are listed too
    blocks = []
    for group in groups or GROUPS:
        rows = entries(group)
        width = max((len(n) for n, _ in rows), default=0)
        lines = [f"{group} ({GROUPS[group][0]}):"]
        lines += [f"  {n.ljust(width)}  {d}".rstrip() for n, d in rows]
        blocks.append("\n".join(lines))
    return "\n\n".join(blocks)
