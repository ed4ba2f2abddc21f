"""Rayleigh damping ``f = -(alpha M + beta K(x)) v``.

Explicit integrators get it inside ``system.force`` (``K`` applied matrix-free, unfixed);
implicit ones read ``system.rayleigh == (alpha, beta)``, call ``force(..., rayleigh=False)``
and build the term into their matrix (the form of SOFA's EulerImplicitSolver documentation).
It is not part of ``damping_matrix`` (so it is never counted twice).
"""

from __future__ import annotations

from .base import Force, nonnegative


class RayleighDamping(Force):
    """Rayleigh damping with mass coefficient ``alpha`` (1/s) and stiffness coefficient ``beta`` (s)."""

    kind = None

    def __init__(self, alpha: float = 0.0, beta: float = 0.0):
        self.alpha = nonnegative(alpha, "Rayleigh alpha (mass)")
        self.beta = nonnegative(beta, "Rayleigh beta (stiffness)")

    def add_force(self, x, v, t, out) -> None:
        s = self._system
        if self.alpha:
            out -= self.alpha * s.mass[:, None] * v
        if self.beta:
            out -= self.beta * s.hessian_product(x, v)

    def __repr__(self) -> str:
        return f"RayleighDamping(alpha={self.alpha!r}, beta={self.beta!r})"
