"""The few PETSc C functions petsc4py 3.18 does not wrap, called through ctypes.

petsc4py 3.18 (Debian's) has no ``Mat.setPreallocationCOO`` / ``Mat.setValuesCOO`` and no
``Options.used``; the C library it is linked to has them (``MatSetPreallocationCOO``,
``MatSetValuesCOO``, ``PetscOptionsUsed``, PETSc >= 3.16). The library is the one already
loaded into this process by petsc4py (found in ``/proc/self/maps``), so the handles
(``obj.handle``) are valid for it. Newer petsc4py versions' own methods are preferred.
"""

from __future__ import annotations

import ctypes
from functools import lru_cache

from ...errors import BackendUnavailableError

INSERT_VALUES = 1  # PETSc's InsertMode


@lru_cache(maxsize=1)
def library() -> ctypes.CDLL:
    """The loaded ``libpetsc*.so`` with argument types of the functions used here declared."""
    path = None
    try:
        with open("/proc/self/maps") as fh:
            for line in fh:
                part = line.split()[-1]
                if "/libpetsc" in part and ".so" in part:
                    path = part
                    break
    except OSError:
        path = None
    if path is None:
        raise BackendUnavailableError("the PETSc C library loaded by petsc4py was not found in "
                                      "/proc/self/maps (Linux only)")
    lib = ctypes.CDLL(path)
    lib.MatSetPreallocationCOO.argtypes = [ctypes.c_void_p, ctypes.c_int64, ctypes.c_void_p,
                                           ctypes.c_void_p]
    lib.MatSetValuesCOO.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int]
    lib.PetscOptionsUsed.argtypes = [ctypes.c_void_p, ctypes.c_char_p,
                                     ctypes.POINTER(ctypes.c_int)]
    for fn in (lib.MatSetPreallocationCOO, lib.MatSetValuesCOO, lib.PetscOptionsUsed):
        fn.restype = ctypes.c_int
    return lib


def check(code: int, what: str) -> None:
    """Raise ``RuntimeError`` for a non-zero PETSc error code."""
    if code:
        raise RuntimeError(f"{what} failed with PETSc error code {code}")


def option_used(name: str) -> bool:
    """``PetscOptionsUsed`` on the global options database (``name`` without the leading ``-``,
    as PETSc 3.18 stores it)."""
    flag = ctypes.c_int(0)
    check(library().PetscOptionsUsed(None, name.encode(), ctypes.byref(flag)), "PetscOptionsUsed")
    return bool(flag.value)
