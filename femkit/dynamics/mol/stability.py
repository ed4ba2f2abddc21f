"""The largest eigenvalue of ``M^-1 K`` on the free nodes and the critical step of a scheme.

``lambda_max`` of the pencil ``K_ff x = lambda M_ff x`` by Lanczos (ARPACK through SciPy's
``eigsh``): with a lumped (diagonal) mass on the symmetric ``D^-1/2 K D^-1/2``, with a
consistent mass in ARPACK's generalised mode with ``M``'s kept factor as ``M^-1``. Lanczos'
Ritz value approaches ``lambda_max`` from below, like the power iteration of
:func:`femkit.dynamics.stability.estimate_omega_max`, to a relative ``1e-10`` here.

>>> import numpy as np, scipy.sparse as sp
>>> from femkit.dynamics.mol import LinearSystem
>>> K = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(5, 5))
>>> s = LinearSystem(sp.identity(5), K, fixed=[], lumped=True)
>>> bool(abs(largest_eigenvalue(s) - (2 + 2 * np.cos(np.pi / 6))) < 1e-12)
True
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["largest_eigenvalue", "critical_step"]

#: Relative tolerance of the Lanczos eigenvalue.
EIG_TOL = 1e-10


def largest_eigenvalue(system) -> float:
    """``lambda_max(M_ff^-1 K_ff)`` of a :class:`~femkit.dynamics.mol.LinearSystem`."""
    from scipy.sparse.linalg import LinearOperator, eigsh

    free = system.free
    n = free.size
    if n == 0:
        return 0.0
    K = system.K[free][:, free].tocsr()
    if n <= 200:  # dense: exact and faster than ARPACK at this size
        import scipy.linalg as la

        M = system.M[free][:, free].toarray()
        return float(la.eigh(K.toarray(), M, eigvals_only=True)[-1])
    v0 = np.random.default_rng(0).standard_normal(n)
    if system.lumped:
        w = 1.0 / np.sqrt(system.M.diagonal()[free])
        S = (sp.diags(w) @ K @ sp.diags(w)).tocsr()
        return float(eigsh(S, k=1, which="LA", tol=EIG_TOL, v0=v0,
                           return_eigenvectors=False)[0])
    op = system.operator(1.0, 0.0)
    Minv = LinearOperator((n, n), matvec=op.solve_free, dtype=np.float64)
    M = system.M[free][:, free].tocsr()
    return float(eigsh(K, k=1, M=M, Minv=Minv, which="LA", tol=EIG_TOL, v0=v0,
                       return_eigenvectors=False)[0])


def critical_step(scheme, system) -> tuple[float, float]:
    """``(dt_crit, lambda_max)`` of ``scheme`` on ``system`` (``dt_crit`` is ``inf`` for an
    unconditionally stable scheme, which computes no eigenvalue)."""
    import math

    if math.isinf(scheme.stability_bound):
        return math.inf, float("nan")
    lam = largest_eigenvalue(system)
    return scheme.critical_step(lam), lam
