"""Load-time checks shared by every problem type (Poisson cases, mass-spring scenes).

Each check looks names up in the live registries (so a newly registered solver, preconditioner
or geometry is accepted without touching a schema) and raises the registry's own exception
with the key path in front of its message, e.g.
``solver.method: unknown solver 'bicgstab'; valid solvers: cg, direct, ...``.

>>> spec = {"method": "pcg"}
>>> check_solver_spec(spec, "solver", default_preconditioner="amg")
>>> spec["preconditioner"]
'amg'
>>> check_solver_spec({"method": "cg", "preconditioner": "ic0"}, "solver", "amg")
Traceback (most recent call last):
...
femkit.errors.CaseFileError: solver.preconditioner: 'ic0' needs method 'pcg', not 'cg' (drop it or use method: pcg)
"""

from __future__ import annotations

import inspect
from pathlib import Path

from ..errors import CaseFileError, InputError, UnknownNameError

__all__ = ["with_prefix", "lookup", "check_solver_spec", "check_geometry_spec", "resolve_file"]


def with_prefix(exc: InputError, where: str) -> InputError:
    """The same exception (type and attributes kept) with ``where: `` before its one-line message."""
    cls = type(exc)
    new = cls.__new__(cls)
    new.__dict__.update(exc.__dict__)
    new.args = (f"{where}: {' '.join(str(exc).split())}",)
    return new


def lookup(registry, name: str, where: str):
    """``registry.get(name)``; an unknown name raises UnknownNameError prefixed with ``where``."""
    try:
        return registry.get(name)
    except UnknownNameError as exc:
        raise with_prefix(exc, where) from None


def check_solver_spec(spec: dict, where: str, default_preconditioner: str) -> None:
    """Check ``spec["method"]`` and ``spec["preconditioner"]`` against the solver registries.

    A missing (or null) preconditioner becomes ``default_preconditioner`` for ``pcg`` and
    ``none`` otherwise (``spec`` is updated in place). A preconditioner other than ``none``
    with a method other than ``pcg`` is a :class:`CaseFileError`.

    Parameters
    ----------
    spec : dict
        The validated solver mapping (``method``, optional ``preconditioner``).
    where : str
        Key path of the mapping in the file (``"solver"``, ``"linear_solver"``).
    default_preconditioner : str
        Preconditioner ``pcg`` gets when none is given.
    """
    from ..solvers.registry import PRECONDITIONERS, SOLVERS

    lookup(SOLVERS, spec["method"], f"{where}.method")
    if spec.get("preconditioner") is None:
        spec["preconditioner"] = default_preconditioner if spec["method"] == "pcg" else "none"
    lookup(PRECONDITIONERS, spec["preconditioner"], f"{where}.preconditioner")
    if spec["preconditioner"] != "none" and spec["method"] != "pcg":
        raise CaseFileError(f"{where}.preconditioner: {spec['preconditioner']!r} needs method "
                            f"'pcg', not {spec['method']!r} (drop it or use method: pcg)")


def check_geometry_spec(spec: dict, where: str) -> None:
    """Check ``spec["geometry"]`` against the geometry registry and ``spec["params"]`` against it.

    ``where`` is the key path of the mapping holding ``geometry``, ``h`` and ``params``
    (``"mesh"``, ``"system"``). Nothing is generated (gmsh is not imported).
    """
    from ..mesh.geometries import GEOMETRIES

    factory = lookup(GEOMETRIES, spec["geometry"], f"{where}.geometry")
    params = spec.get("params") or {}
    signature = inspect.signature(factory)
    try:
        signature.bind(spec["h"], **params)
    except TypeError:
        valid = [p for p in signature.parameters if p != "h"]
        raise CaseFileError(
            f"{where}.params: {sorted(params)} do not fit geometry {spec['geometry']!r}; "
            f"valid parameters: {', '.join(valid) or '(none)'}") from None


def resolve_file(spec: dict, where: str, base: Path) -> None:
    """Make ``spec["file"]`` absolute (against ``base``); CaseFileError when it does not exist."""
    path = (Path(base) / spec["file"]).resolve()
    if not path.is_file():
        raise CaseFileError(f"{where}.file: mesh file not found: {path}")
    spec["file"] = str(path)
