"""Third-party extensions: modules that register kinds, forces, geometries, solvers, ...

A plugin is an ordinary Python module that registers what it adds when imported (a
:class:`~femkit.kinds.Kind` through :func:`~femkit.kinds.register_kind`, a force in
:data:`femkit.case.scene.forces.FORCES`, a geometry in :data:`femkit.mesh.GEOMETRIES`, ...).
femkit imports plugins once, at the first look-up of a file kind (every ``load_case``,
``load_study``, ``femkit solve`` and ``femkit study`` does one), from two places:

* the ``femkit.plugins`` entry-point group of installed packages (what a package declares in
  its ``pyproject.toml``: ``[project.entry-points."femkit.plugins"] heat = "femkit_heat"``);
* the ``FEMKIT_PLUGINS`` environment variable: module names separated by commas (modules on
  ``sys.path``/``PYTHONPATH``), for scripts and experiments without packaging.

A plugin that cannot be imported, or fails while importing (e.g. registers a name twice), is an
:class:`~femkit.errors.InputError` naming it (exit 2).
"""

from __future__ import annotations

import functools
import importlib
import os

from .errors import InputError

__all__ = ["ENTRY_POINT_GROUP", "ENV_VAR", "load_plugins", "plugin_names"]

ENTRY_POINT_GROUP = "femkit.plugins"
ENV_VAR = "FEMKIT_PLUGINS"

_loaded: set[str] = set()


def plugin_names() -> list[tuple[str, str]]:
    """``(where, module)`` of every plugin: entry points first, then ``FEMKIT_PLUGINS``."""
    out = list(_entry_point_plugins())
    for name in os.environ.get(ENV_VAR, "").split(","):
        if name.strip():
            out.append((ENV_VAR, name.strip()))
    return out


@functools.lru_cache(maxsize=None)
def _entry_point_plugins() -> tuple[tuple[str, str], ...]:
    """The entry-point plugins, read once per process: every file-kind look-up asks, and each
    reading scans the metadata of every installed distribution (~10-20 ms)."""
    out = []
    try:
        from importlib.metadata import entry_points

        for ep in entry_points(group=ENTRY_POINT_GROUP):
            out.append((f"entry point {ep.name!r} ({ENTRY_POINT_GROUP})", ep.value.split(":")[0]))
    except Exception:  # a broken distribution's metadata must not stop femkit
        pass
    return tuple(out)


def load_plugins() -> list[str]:
    """Import every plugin module not yet imported; returns the modules imported now."""
    done = []
    for where, module in plugin_names():
        if module in _loaded:
            continue
        _loaded.add(module)
        try:
            importlib.import_module(module)
        except ImportError as exc:
            raise InputError(f"plugin {module!r} from {where} cannot be imported: {exc}") from None
        except Exception as exc:  # a plugin's own error (e.g. a name registered twice)
            raise InputError(f"plugin {module!r} from {where} failed while importing: "
                             f"{type(exc).__name__}: {exc}") from None
        done.append(module)
    return done
