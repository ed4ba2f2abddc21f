"""Compile the elastic solids' kernels ahead: part of ``femkit warmup``.

The built-in materials' kernels are generated from their energy expressions
(:mod:`femkit.solids.materials.builtin_kernels`) into femkit's cache directory and compiled by numba on
first use (about a minute on a loaded machine). :func:`warm_up` does both now, on a tiny
triangle and tetrahedron body, P1 and P2: the element pass and its form at quadrature points
(every level, projected or not: one compilation each, the arguments' types are those of any
body), the point function and the stretch
energy. Afterwards a process loads the module and its machine code from the cache, without
SymPy. A material a user designs by its energy is generated and compiled on its own first use.
"""

from __future__ import annotations

import time

import numpy as np

__all__ = ["warm_up"]


def warm_up() -> float:
    """Generate (or load) and compile the built-in materials' kernels; seconds taken."""
    from .body import ElasticBody, point_tangent
    from .materials import material

    t0 = time.perf_counter()
    tri = (np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), np.array([[0, 1, 2]]))
    tet = (np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]), np.array([[0, 1, 2, 3]]))
    for name in ("linear", "stable_neo_hookean"):
        mat = material(name, mu=1.0, lam=1.0)
        for X, cells in (tri, tet):
            for element in ("P1", "P2"):          # P2: the element pass at quadrature points
                body = ElasticBody(X, cells, mat, element=element)
                x = body.rest_positions * 1.1
                body.evaluate(x, 2, project=True)
                body.stresses(x)
            point_tangent(mat, np.eye(X.shape[1]))
        if name != "linear":
            mat.stretch_derivatives(np.ones(3))
    return time.perf_counter() - t0
