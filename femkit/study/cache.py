"""No result cache, by design; a content fingerprint instead.

femkit studies recompute every run each time they are run: a study of the bundled size takes
seconds to minutes, and a cache keyed on anything less than the full content of every input
(the study file, the case/mesh files it names, the femkit source) could serve stale numbers.
What this module gives instead is a *fingerprint*: the SHA-256 of the study file's bytes, of
every file it references, and of the femkit version, written into ``results.json``. Two reports
with the same fingerprint came from the same inputs; a report directory is always replaced
whole (see :mod:`femkit.study.report`), so no file from an earlier run survives a re-run.

>>> len(fingerprint([], extra={"a": 1}))
64
"""

from __future__ import annotations

import hashlib
import json
import os
from typing import Iterable

__all__ = ["fingerprint"]


def fingerprint(paths: Iterable[str | os.PathLike], *, extra: dict | None = None) -> str:
    """SHA-256 over the bytes of ``paths`` (in the given order), ``extra`` (JSON) and femkit's version."""
    from .._version import __version__

    h = hashlib.sha256()
    h.update(f"femkit {__version__}\n".encode())
    for p in paths:
        p = os.fspath(p)
        h.update(os.path.basename(p).encode() + b"\0")
        with open(p, "rb") as fh:
            h.update(hashlib.sha256(fh.read()).digest())
    if extra:
        h.update(json.dumps(extra, sort_keys=True, default=str).encode())
    return h.hexdigest()
