"""The bytecode writer of ``femkit warmup``: every femkit module's ``.pyc``, also where Python
writes none itself."""

from __future__ import annotations


def byte_compile(root: str | None = None) -> tuple[int, int]:
    """Write the bytecode (``__pycache__/*.pyc``) of every module under ``root`` (default: the
    installed femkit package); ``(modules written or up to date, modules that failed)``.

    Python reads a ``.pyc`` whenever it is up to date with its source, but writes none under
    ``PYTHONDONTWRITEBYTECODE=1`` or where it cannot write: each process then compiles every
    femkit module it imports from source again (about 0.2 s of a ``femkit solve``).
    :mod:`py_compile` writes regardless of that variable. A source edited later makes its
    ``.pyc`` stale (its recorded modification time differs), and Python ignores it.
    """
    import os
    import py_compile
    from importlib.util import cache_from_source

    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # femkit/
    base = root if root is not None else package
    written = failed = 0
    for folder, dirs, files in os.walk(base):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__" and not d.startswith("."))
        for name in sorted(files):
            if not name.endswith(".py"):
                continue
            source = os.path.join(folder, name)
            try:
                py_compile.compile(source, cfile=cache_from_source(source), doraise=True)
                written += 1
            except (py_compile.PyCompileError, OSError):
                failed += 1
    return written, failed
