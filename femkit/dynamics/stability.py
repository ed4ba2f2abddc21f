"""Largest angular frequency of a mass-spring system and the critical explicit step.

For the linearisation ``M x'' = -K x`` on the free dofs the angular frequencies are
``omega = sqrt(lambda)`` of the symmetric pencil, i.e. of ``S = M^-1/2 K M^-1/2`` (same
eigenvalues as ``M^-1 K``, but symmetric, so power iteration with the Rayleigh quotient
converges at the squared rate). An explicit method with stability bound ``b`` (``h omega``
limit: 2 for symplectic Euler / Verlet, ``2 sqrt 2`` for RK4) is stable for
``dt <= b / omega_max``.

>>> from femkit.dynamics.topology import single_spring
>>> s = single_spring(k=100.0, m=1.0, gravity=None)
>>> round(estimate_omega_max(s), 10)          # sqrt(k/m)
10.0
>>> critical_dt(10.0, 2.0)
0.2
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

__all__ = ["estimate_omega_max", "omega_upper_bound", "critical_dt", "scaled_stiffness"]


def scaled_stiffness(system, x=None, *, fix: str | None = None) -> sp.csr_matrix:
    """``S = M_f^-1/2 K_ff M_f^-1/2`` on the free dofs at ``x`` (default ``system.x0``)."""
    x = system.x0 if x is None else x
    K = system.free_block(system.stiffness_matrix(x, fix=fix))
    w = 1.0 / np.sqrt(np.repeat(system.mass, system.dim)[system.free_dofs])
    Dw = sp.diags(w)
    return (Dw @ K @ Dw).tocsr()


def estimate_omega_max(system, x=None, iters: int = 500, *, tol: float = 1e-10, random_state: int = 0,
                       fix: str | None = None) -> float:
    """``omega_max = sqrt(|lambda_max|)`` of ``M^-1 K`` on the free dofs, by power iteration.

    Parameters
    ----------
    system : MassSpringSystem
    x : (n, d) positions of the linearisation (default ``system.x0``).
    iters : maximum number of power iterations.
    tol : stop when the Rayleigh quotient changes by less than ``tol`` relatively.
    random_state : key of the random start vector (deterministic by default).
    fix : definiteness fix passed to ``stiffness_matrix``.

    Returns
    -------
    float
        The estimate (a lower bound of the true value up to round-off: the Rayleigh quotient
        never exceeds ``|lambda|_max``). 0 when there are no free dofs or no stiffness.
        :func:`omega_upper_bound` gives a guaranteed (Gershgorin) upper bound.
    """
    S = scaled_stiffness(system, x, fix=fix)
    m = S.shape[0]
    if m == 0 or S.nnz == 0:
        return 0.0
    rng = np.random.default_rng(random_state)
    z = rng.standard_normal(m)
    z /= np.linalg.norm(z)
    lam = 0.0
    for _ in range(max(1, int(iters))):
        y = S @ z
        new = float(z @ y)
        ny = np.linalg.norm(y)
        if ny == 0.0:
            return 0.0
        z = y / ny
        if abs(new - lam) <= tol * abs(new):
            lam = new
            break
        lam = new
    # the Rayleigh quotient of the last iterate is the sharper estimate of |lambda|_max
    lam = max(abs(lam), abs(float(z @ (S @ z))))
    return math.sqrt(lam)


def omega_upper_bound(system, x=None) -> float:
    """Gershgorin upper bound ``sqrt(max_row sum_col |S_rc|)`` of ``omega_max``."""
    S = scaled_stiffness(system, x)
    if S.shape[0] == 0:
        return 0.0
    return math.sqrt(float(abs(S).sum(axis=1).max()))


def critical_dt(omega_max: float, bound: float) -> float:
    """Critical explicit step ``bound / omega_max`` (``inf`` when ``omega_max == 0`` or ``bound`` is infinite)."""
    if omega_max <= 0.0 or math.isinf(bound):
        return math.inf
    return bound / omega_max
