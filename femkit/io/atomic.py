"""Atomic writes: a reader never sees a half-written file or a half-built output directory.

Files are written to a temporary file in the same directory, flushed and fsynced, then moved
into place with :func:`os.replace` (atomic on POSIX and Windows within one file system).
An output directory is built as ``<dir>.tmp-XXXX`` next to its final place and renamed into
place only when everything in it was written; an older run at ``<dir>`` is replaced only then.

>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> with atomic_directory(d / "run") as tmp:
...     _ = atomic_write_text(tmp / "a.txt", "hello")
>>> (d / "run" / "a.txt").read_text()
'hello'
>>> sorted(p.name for p in d.iterdir())
['run']
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from ..errors import InputError

__all__ = ["atomic_write_text", "atomic_write_bytes", "atomic_path", "atomic_directory",
           "check_output_dir"]


#: Files that mark a directory as an earlier femkit output of each kind (a run of a case or a
#: scene; a study report): :func:`check_output_dir` lets a new output of the same kind replace it.
EARLIER_RUN = ("result.json",)
EARLIER_REPORT = ("results.json", "report.md")


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:  # e.g. Windows: directories cannot be opened
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on success it replaces ``path``.

    For writers that want a file name (meshio, matplotlib). The temporary name keeps the
    extension of ``path`` (``suffix``) so format detection by extension works.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix or target.suffix,
                               dir=target.parent)
    os.close(fd)
    # mkstemp creates the file -rw------- whatever the umask; a file written any other way would
    # get 0o666 & ~umask. Give the result the same mode (result.json next to solution.vtu).
    os.chmod(tmp, 0o666 & ~_umask())
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        with open(tmp_path, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp_path, target)
        _fsync_dir(target.parent)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        raise


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; returns the path."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    return Path(path)


def atomic_write_text(path: str | os.PathLike, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically; returns the path."""
    return atomic_write_bytes(path, text.encode(encoding))


def check_output_dir(path: str | os.PathLike, previous: tuple[str, ...] | None = None) -> Path:
    """Check that :func:`atomic_directory` may build ``path``; return it resolved.

    Parameters
    ----------
    path : the output directory.
    previous : names of files that mark a directory as an earlier run of the same kind
        (e.g. ``("result.json",)``). When given, an existing non-empty directory holding none
        of them is refused: replacing it would delete files femkit did not write (an output
        directory set to ``.`` or to a project folder).

    Raises
    ------
    InputError
        ``path`` or one of its parents exists but is not a directory, its parent does not accept
        new files (permissions, a read-only file system), or (with ``previous``)
        ``path`` is a non-empty directory that is not an earlier femkit output.

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "notes.txt").write_text("mine")
    >>> check_output_dir(d, previous=("result.json",))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    femkit.errors.InputError: output directory ... exists and is not a femkit output ...
    """
    final = Path(path).resolve()
    for p in (final, *final.parents):
        if p.exists() and not p.is_dir():
            where = "" if p == final else f" (its parent {p} is a file)"
            raise InputError(f"output directory {final} is not a directory{where}; "
                             "choose another output directory")
    _check_writable(final)
    if previous is not None and final.is_dir():
        entries = {e.name for e in final.iterdir()}
        if entries and not entries & set(previous):
            raise InputError(
                f"output directory {final} exists and is not a femkit output (it holds "
                f"{len(entries)} entries but no {' or '.join(previous)}); a run replaces its "
                "output directory as a whole, so choose a new or empty directory")
    return final


def _check_writable(final: Path) -> None:
    """Refuse, before any work, an output directory whose temporary sibling cannot be created.

    The output is built next to ``final`` (in its parent, made if missing), so the nearest
    existing ancestor of that parent must accept a new entry. A real probe (create and remove a
    temporary file) rather than ``os.access``: it also catches read-only file systems, and
    root, whom ``os.access`` never refuses.
    """
    parent = final.parent
    existing = next(p for p in (parent, *parent.parents) if p.exists())
    try:
        fd, probe = tempfile.mkstemp(prefix=".femkit-write-probe-", dir=existing)
    except OSError as exc:
        raise InputError(f"output directory {final} cannot be written: {existing} does not accept "
                         f"new files ({exc.strerror or exc}); choose another output directory "
                         "(--output DIR)") from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)


@contextlib.contextmanager
def atomic_directory(path: str | os.PathLike,
                     previous: tuple[str, ...] | None = None) -> Iterator[Path]:
    """Build a directory under a temporary name and move it to ``path`` on success.

    On an exception the temporary directory is removed and ``path`` (an older run, if any)
    is left untouched. On success an existing ``path`` is moved aside, the new directory
    renamed into place, and the old one deleted. Before anything is created,
    :func:`check_output_dir` (with ``previous``) refuses a ``path`` that is a file, lies below
    a file, or (with ``previous``) is a directory of other files.
    """
    final = check_output_dir(path, previous)
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f"{final.name}.tmp-", dir=final.parent))
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    old = None
    if final.exists():
        old = Path(tempfile.mkdtemp(prefix=f"{final.name}.old-", dir=final.parent))
        os.rmdir(old)
        os.replace(final, old)
    try:
        os.replace(tmp, final)
    except BaseException:
        if old is not None:
            os.replace(old, final)
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    os.chmod(final, 0o755 & ~_umask())
    _fsync_dir(final.parent)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
