"""The tables of Bey's red refinement of a tetrahedron (Bey 1995, "Tetrahedral grid refinement",
Computing 55): its eight children in local vertex ids, and the midpoint pairs they join.

Shared by the NumPy path (:mod:`femkit.mesh.refine`) and the compiled passes
(:mod:`femkit.mesh._refine_kernel`).
"""

from __future__ import annotations

import numpy as np

#: Local vertices of a tetrahedron during refinement: v0..v3, then the midpoints of its edges in
#: :data:`~femkit.mesh.edges.LOCAL_EDGES` order, m01 m02 m03 m12 m13 m23 (ids 4..9).
CORNERS = np.array([[0, 4, 5, 6], [4, 1, 7, 8], [5, 7, 2, 9], [6, 8, 9, 3]])
#: The inner octahedron cut along diagonal m01-m23, m02-m13 or m03-m12: the four tetrahedra
#: around the diagonal (its ends, then consecutive vertices of the equator).
INNER = np.array([
    [[4, 9, 5, 6], [4, 9, 6, 8], [4, 9, 8, 7], [4, 9, 7, 5]],     # m01-m23; equator m02 m03 m13 m12
    [[5, 8, 4, 6], [5, 8, 6, 9], [5, 8, 9, 7], [5, 8, 7, 4]],     # m02-m13; equator m01 m03 m23 m12
    [[6, 7, 4, 5], [6, 7, 5, 9], [6, 7, 9, 8], [6, 7, 8, 4]],     # m03-m12; equator m01 m02 m23 m13
])
DIAGONALS = np.array([[4, 9], [5, 8], [6, 7]])

#: The pairs of a tetrahedron's local edges (:data:`femkit.mesh.mesh.LOCAL_EDGES` order 01 02
#: 03 12 13 23) whose midpoints Bey's children join: three per face (faces 123, 023, 013, 012),
#: then the inner diagonal of each choice (m01-m23, m02-m13, m03-m12).
FACE_PAIRS = np.array([[3, 4], [3, 5], [4, 5], [1, 2], [1, 5], [2, 5],
                       [0, 2], [0, 4], [2, 4], [0, 1], [0, 3], [1, 3]], np.int64)
DIAGONAL_PAIRS = np.array([[0, 5], [1, 4], [2, 3]], np.int64)
