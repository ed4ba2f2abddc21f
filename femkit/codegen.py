"""Generated Python modules: written once to femkit's cache directory and imported from there.

femkit turns some user input into numba source (an elastic energy's derivatives, the
expressions of a case file). The text of such a module is written to ``FEMKIT_CACHE_DIR`` (else
``~/.cache/femkit``) under a name that hashes the text (and whatever else it depends on, the
``salt``), then imported; numba's ``cache=True`` keeps its machine code beside it, so a later
process pays neither the generation nor the compilation. A generated module reuses compiled
template functions of a library module by copying their source in (:func:`copied_kernels`):
their globals then resolve to the generated definitions.

Standard library only: any layer may import it.
"""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import os
import sys
import tempfile
from pathlib import Path
from types import ModuleType
from typing import Callable, Iterable

__all__ = ["cache_dir", "load_generated", "load_named", "copied_kernels", "function_sources", "generated_path",
           "find_generated"]

_LOADED: dict[str, ModuleType] = {}


def cache_dir(kind: str) -> Path:
    """Where generated modules of ``kind`` live (``FEMKIT_CACHE_DIR`` or ``~/.cache/femkit``)."""
    root = os.environ.get("FEMKIT_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "femkit")
    return Path(root) / kind


def _name(text: str, prefix: str, salt: str) -> str:
    return f"{prefix}_{hashlib.sha256((text + salt).encode()).hexdigest()[:20]}"


def generated_path(text: str, prefix: str, kind: str, salt: str = "") -> Path:
    """The file :func:`load_generated` writes ``text`` to (whether or not it exists yet)."""
    return cache_dir(kind) / f"{_name(text, prefix, salt)}.py"


def load_generated(text: str, prefix: str, kind: str, salt: str = "") -> ModuleType:
    """The module whose source is ``text``: written once to :func:`cache_dir` (``kind``) under
    ``<prefix>_<hash of text + salt>.py``, imported once per process.

    ``salt`` is what the module depends on beyond its own text (e.g. the source of the module it
    imports its shared kernels from: numba's cache would not notice an edited callee).
    """
    return load_named(_name(text, prefix, salt), kind, lambda: text, rewrite=True)


def load_named(name: str, kind: str, make_text: Callable[[], str], *,
               rewrite: bool = False) -> ModuleType:
    """The generated module ``name`` of :func:`cache_dir` (``kind``), imported once per process;
    its text is made by ``make_text()`` only when the file is missing (or differs, with
    ``rewrite``), so a caller whose ``name`` already hashes everything the text depends on loads
    a cached module without generating it. Written atomically."""
    mod = _LOADED.get(name)
    if mod is not None:
        return mod
    path = find_generated(name, kind) or cache_dir(kind) / f"{name}.py"
    if not path.exists() or rewrite:
        text = make_text()
        if not path.exists() or path.read_text() != text:
            try:
                _write_atomic(path, text)
            except OSError as exc:  # a read-only cache (or HOME): a private temporary one
                path = _fallback_dir(kind, path.parent, exc) / path.name
                _write_atomic(path, text)
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    _LOADED[name] = mod
    return mod


def find_generated(name: str, kind: str) -> Path | None:
    """The file of the generated module ``name`` of ``kind``: in :func:`cache_dir`, else in the
    private temporary directory a run without a writable cache put it in; None when neither
    holds it (it was never generated here)."""
    path = cache_dir(kind) / f"{name}.py"
    if path.is_file():
        return path
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if folder.is_dir() and os.access(folder, os.W_OK):
        return None  # a writable (or makeable) cache: nothing went to the temporary one
    fallback = _private_temp() / kind / f"{name}.py"
    return fallback if fallback.is_file() else None


def _write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)      # atomic: parallel test workers may write the same file


_WARNED: set[str] = set()


def _private_temp() -> Path:
    """``<tmp>/femkit-cache-<uid>``, made private (0700) and checked to be this user's own real
    directory (modules imported from it run as code); else a fresh ``mkdtemp`` one."""
    import stat

    uid = getattr(os, "getuid", lambda: None)()
    root = Path(tempfile.gettempdir()) / f"femkit-cache-{uid}"
    try:
        root.mkdir(mode=0o700, exist_ok=True)
        st = os.lstat(root)
        if stat.S_ISDIR(st.st_mode) and (uid is None or st.st_uid == uid) \
                and not st.st_mode & 0o077:
            return root
    except OSError:
        pass
    return Path(tempfile.mkdtemp(prefix="femkit-cache-"))


def _fallback_dir(kind: str, wanted: Path, exc: OSError) -> Path:
    """A directory of this user's under the system's temporary one, for generated modules of
    ``kind`` when ``wanted`` cannot be written; says so once per process (one line on stderr:
    the modules, and their compiled code, are then made again after the temporary files go)."""
    folder = _private_temp() / kind
    if str(wanted) not in _WARNED:
        _WARNED.add(str(wanted))
        reason = exc.strerror or type(exc).__name__
        print(f"femkit: warning: cannot write the kernel cache {wanted} ({reason}); using "
              f"{folder} instead (set FEMKIT_CACHE_DIR to a writable directory to keep them)",
              file=sys.stderr)
    return folder


def copied_kernels(module: ModuleType, roots: Iterable[str]) -> list[str]:
    """Names of the compiled functions of ``module`` that reach one of ``roots`` through their
    calls or reads of globals (read from each function's code object; a root, a function or a
    constant, need not be defined in ``module``), in source order: a generated module copies
    their source, so that they resolve its own definitions of ``roots``; it imports the others."""
    funcs = {n: f.py_func for n, f in vars(module).items() if hasattr(f, "py_func")}
    reach = set(roots)
    calls = {n: set(f.__code__.co_names) & (set(funcs) | reach) for n, f in funcs.items()}
    grew = True
    while grew:
        new = {n for n, c in calls.items() if c & reach} - reach
        reach |= new
        grew = bool(new)
    reach -= set(roots)
    return sorted(reach, key=lambda n: funcs[n].__code__.co_firstlineno)


def function_sources(module: ModuleType, names: Iterable[str]) -> list[str]:
    """The source text of each function ``names`` of ``module`` (decorators included)."""
    return [inspect.getsource(getattr(module, n)).rstrip() for n in names]
