"""Load-time name checks shared by every file kind (Poisson cases, mass-spring scenes, studies).

Each check looks names up in the live registries (so a newly registered solver, preconditioner
or geometry is accepted without touching a schema) and raises the registry's own exception
with the key path in front of its message, e.g.
``solver.method: unknown solver 'bicgstab'; valid solvers: cg, direct, ...``.

>>> from femkit.solvers import SOLVERS
>>> lookup(SOLVERS, "bicgstab", "solver.method")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
femkit.errors.UnknownNameError: solver.method: unknown solver 'bicgstab'; valid solvers: cg, cholesky, ...
"""

from __future__ import annotations

from pathlib import Path

from ..errors import CaseFileError, InputError, UnknownNameError, with_prefix

__all__ = ["with_prefix", "lookup", "check_options", "check_geometry_spec", "resolve_file"]


def lookup(registry, name: str, where: str):
    """``registry.get(name)``; an unknown name raises UnknownNameError prefixed with ``where``."""
    try:
        return registry.get(name)
    except UnknownNameError as exc:
        raise with_prefix(exc, where) from None


def check_options(fn, options: dict, where: str, exclude=()) -> None:
    """Unknown keyword options of ``fn`` are a CaseFileError naming ``where`` and the valid ones."""
    from ..solvers.core.checks import check_options as _check

    try:
        _check(fn, options, what=where.rsplit(".", 1)[0], exclude=exclude)
    except InputError as exc:
        raise CaseFileError(f"{where}: {exc}") from None


def check_geometry_spec(spec: dict, where: str) -> None:
    """Check ``spec["geometry"]`` against the geometry registry and ``spec["params"]`` against it.

    ``where`` is the key path of the mapping holding ``geometry``, ``h`` and ``params``
    (``"mesh"``, ``"system"``). Nothing is generated (gmsh is not imported).
    """
    from ..mesh.geometries import GEOMETRIES

    entry = lookup(GEOMETRIES, spec["geometry"], f"{where}.geometry")
    params = spec.get("params") or {}
    try:
        entry.check_params(spec["h"], params)
    except InputError:
        raise CaseFileError(
            f"{where}.params: {sorted(params)} do not fit geometry {spec['geometry']!r}; "
            f"valid parameters: {', '.join(entry.parameters) or '(none)'}") from None


def resolve_file(spec: dict, where: str, base: Path) -> None:
    """Make ``spec["file"]`` absolute (against ``base``); CaseFileError when it does not exist."""
    path = Path(base) / spec["file"]
    try:
        path = path.resolve()
    except (OSError, RuntimeError):  # Python 3.11 raises RuntimeError on a symlink loop
        raise CaseFileError(f"{where}.file: mesh file is a symbolic link loop: "
                            f"{path.absolute()}") from None
    if not path.is_file():
        raise CaseFileError(f"{where}.file: mesh file not found: {path}")
    spec["file"] = str(path)
