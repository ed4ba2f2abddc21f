"""The global solve of the local/global methods with some nodes held in some components only.

Fast mass-spring (Liu et al. 2013) and projective dynamics (Bouaziz et al. 2014) factorise one
``n x n`` matrix ``A`` that serves every coordinate: the coordinates decouple. A node pinned in
every component is eliminated from all of them at once (its row dropped, its position moved to
the right-hand side). A roller holds a node in some components only, so coordinate ``c`` has its
own set of held nodes: :class:`ComponentSolve` eliminates them per coordinate, one factorisation
of ``A`` restricted to the nodes free in ``c`` per distinct set (at most ``d``, built once per
run; coordinates without a roller share the factor of the nodes free in any component). The
held entries come back exactly as given, so a held component never moves.

>>> import numpy as np, scipy.sparse as sp
>>> from femkit.solvers.direct import factorize
>>> A = sp.csr_matrix(np.array([[2., -1., 0.], [-1., 2., -1.], [0., -1., 2.]]))
>>> held = np.array([[False, False], [True, False], [False, False]])   # node 1 held in x
>>> s = ComponentSolve(A, held, lambda B: _Wrap(factorize(B)))
>>> X = s.solve(np.ones((3, 2)), np.array([[0., 0.], [5., 0.], [0., 0.]]))
>>> X[:, 0].tolist(), float(X[1, 1])
([3.0, 5.0, 3.0], 2.0)
"""

from __future__ import annotations

import numpy as np

__all__ = ["ComponentSolve"]


class _Wrap:  # a solve function as a factor (the doctest's SuperLU)
    def __init__(self, solve):
        self.solve = solve


class ComponentSolve:
    """``A X = B`` on the free rows with, per column ``c``, the rows ``held[:, c]`` fixed.

    Parameters
    ----------
    A : sparse ``(m, m)``
        The matrix on the nodes free in some component (already without the fully pinned ones).
    held : ``(m, d)`` bool
        The components held among those nodes.
    factorize : callable
        ``factorize(B) -> factor`` with ``factor.solve(rhs)`` for ``rhs`` of shape ``(k,)`` or
        ``(k, j)`` (the run's ``ctx.session.factorize``).
    """

    def __init__(self, A, held: np.ndarray, factorize):
        import scipy.sparse as sp

        A = sp.csr_matrix(A)
        held = np.asarray(held, dtype=bool)
        self.held = held
        self.groups = []        # (columns, keep rows or None, held rows, factor, A[keep, hold])
        patterns: dict = {}
        for c in range(held.shape[1]):
            patterns.setdefault(held[:, c].tobytes(), []).append(c)
        for key, cols in patterns.items():
            mask = held[:, cols[0]]
            if not mask.any():
                self.groups.append((cols, None, None, factorize(A), None))
                continue
            keep, hold = np.flatnonzero(~mask), np.flatnonzero(mask)
            Ak = A[keep]
            self.groups.append((cols, keep, hold, factorize(Ak[:, keep].tocsr()),
                                Ak[:, hold].tocsr()))

    @property
    def factorizations(self) -> int:
        """Number of factorisations (distinct held sets)."""
        return len(self.groups)

    def solve(self, B: np.ndarray, fixed: np.ndarray) -> np.ndarray:
        """``X`` ``(m, d)`` with ``A X[:, c] = B[:, c]`` on the rows free in ``c`` and
        ``X = fixed`` on the held entries (the other entries of ``fixed`` are not read)."""
        if len(self.groups) == 1 and self.groups[0][1] is None:
            return self.groups[0][3].solve(B)
        out = np.empty(B.shape)
        for cols, keep, hold, factor, A_kh in self.groups:
            if keep is None:
                out[:, cols] = factor.solve(np.asfortranarray(B[:, cols]))
                continue
            held_values = fixed[hold][:, cols]
            rhs = B[keep][:, cols] - A_kh @ held_values
            out[np.ix_(keep, cols)] = factor.solve(np.asfortranarray(rhs)).reshape(len(keep), -1)
            out[np.ix_(hold, cols)] = held_values
        return out
