"""Viscous (air) damping ``f_i = -gamma v_i`` or ``-gamma m_i v_i``."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .base import Force, nonnegative


class ViscousDamping(Force):
    """Damping against the absolute velocity.

    Parameters
    ----------
    gamma : float >= 0
    per_mass : bool
        ``False`` (default): ``f_i = -gamma v_i`` (gamma in kg/s, the issue's formula).
        ``True``: ``f_i = -gamma m_i v_i`` (gamma in 1/s: the same decay rate for every
        particle, i.e. Rayleigh mass damping with ``alpha = gamma``).

    ``D = -df/dv`` is ``gamma I`` (or ``gamma M``).
    """

    kind = None

    def __init__(self, gamma: float, *, per_mass: bool = False):
        self.gamma = nonnegative(gamma, "viscous damping gamma")
        self.per_mass = bool(per_mass)

    def bind(self, system) -> None:
        super().bind(system)
        c = self.gamma * (system.mass if self.per_mass else np.ones(system.n))
        self._coef = c[:, None]
        self._diag = np.repeat(c, system.dim)

    def add_force(self, x, v, t, out) -> None:
        out -= self._coef * v

    def damping(self, x):
        return sp.diags(self._diag, format="csr")

    def __repr__(self) -> str:
        return f"ViscousDamping(gamma={self.gamma!r}, per_mass={self.per_mass})"
