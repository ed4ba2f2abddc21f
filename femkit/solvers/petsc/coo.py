"""Assembling a PETSc matrix from COO triplets: pattern once, values many.

``set_pattern(A, rows, cols)`` (``MatSetPreallocationCOO``) analyses the triplets once
(including entries owned by other ranks, which PETSc communicates); ``set_values(A, values)``
(``MatSetValuesCOO``) then sums repeated entries and assembles, every time the coefficients
change. Negative indices are ignored by PETSc: that is how eliminated (Dirichlet) rows and
columns are dropped. PETSc manual, section "Matrices: COO assembly".
"""

from __future__ import annotations

import ctypes

import numpy as np

from .clib import INSERT_VALUES, check, library
from .env import require_petsc


def set_pattern(A, rows: np.ndarray, cols: np.ndarray) -> None:
    """Declare the COO pattern of ``A`` (global indices, ``-1`` = dropped)."""
    PETSc = require_petsc()
    rows = np.ascontiguousarray(rows, dtype=PETSc.IntType)
    cols = np.ascontiguousarray(cols, dtype=PETSc.IntType)
    if hasattr(A, "setPreallocationCOO"):  # petsc4py >= 3.19
        A.setPreallocationCOO(rows, cols)
        return
    # the C function may permute the index arrays in place: hand it copies (above)
    check(library().MatSetPreallocationCOO(ctypes.c_void_p(A.handle), rows.size,
                                           rows.ctypes.data, cols.ctypes.data),
          "MatSetPreallocationCOO")


def set_values(A, values: np.ndarray) -> None:
    """Set the values of the declared pattern (repeated entries summed) and assemble ``A``."""
    PETSc = require_petsc()
    values = np.ascontiguousarray(values, dtype=PETSc.ScalarType)
    if hasattr(A, "setValuesCOO"):
        A.setValuesCOO(values, addv=PETSc.InsertMode.INSERT_VALUES)
    else:
        check(library().MatSetValuesCOO(ctypes.c_void_p(A.handle), values.ctypes.data,
                                        INSERT_VALUES), "MatSetValuesCOO")
    A.assemble()
