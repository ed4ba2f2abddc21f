"""The protocol every declared force follows (gravity, viscous, Rayleigh, contacts).

A force object is small and data-like; :class:`~femkit.dynamics.system.MassSpringSystem`
calls :meth:`Force.bind` once at construction (precompute per-system arrays) and then,
per evaluation, only the methods below. Every method has a "nothing" default, so a
force implements only what it contributes.

``kind`` names the energy bucket (``"gravity"``, ``"contact"``) or ``None`` for
non-conservative forces. ``constant = True`` declares a force independent of ``x``, ``v``
and ``t`` (gravity): integrators may then evaluate it once per run
(:meth:`~femkit.dynamics.system.MassSpringSystem.constant_force`).
"""

from __future__ import annotations

import numpy as np


class Force:
    """Base class of the declared forces (see module docstring)."""

    kind: str | None = None
    constant: bool = False

    def bind(self, system) -> None:
        """Precompute per-system data (called once by the system)."""
        self._system = system

    def add_force(self, x: np.ndarray, v: np.ndarray, t: float, out: np.ndarray) -> None:
        """Add this force, ``(n, d)``, into ``out``."""

    def energy(self, x: np.ndarray) -> float:
        """Potential energy (0 for non-conservative forces)."""
        return 0.0

    def stiffness(self, x: np.ndarray, fix: str | None = None):
        """Contribution to ``K = -df/dx`` as a sparse matrix, or ``None``."""
        return None

    def structure(self):
        """``(indptr, indices)``: the fixed CSR structure (``ndof x ndof``) of every matrix
        :meth:`stiffness` returns, whose ``data`` is then in this order; ``None`` (the default)
        when the structure changes (contact) or there is no matrix. The compiled implicit
        steps (``cholesky``) build it into their pattern once per run."""
        return None

    def stiffness_product(self, x: np.ndarray, d: np.ndarray, fix: str | None = None):
        """``K_force d`` as ``(n, d)`` (matrix-free), or ``None``."""
        return None

    def negative_bound(self, x: np.ndarray):
        """Per-node bound ``e >= 0`` on the negative part of nodal Jacobian blocks, or ``None``."""
        return None

    def damping(self, x: np.ndarray):
        """Contribution to ``D = -df/dv`` as a sparse matrix, or ``None``."""
        return None


def as_vector(value, dim: int, name: str) -> np.ndarray:
    """A length-``dim`` float vector from ``value``; raises InputError otherwise."""
    from ...errors import InputError

    a = np.asarray(value, dtype=float).ravel()
    if a.shape != (dim,) or not np.all(np.isfinite(a)):
        raise InputError(f"{name} must be {dim} finite numbers for a {dim}D system, got {value!r}")
    return a


def nonnegative(value, name: str) -> float:
    """A finite float ``>= 0``; raises InputError otherwise."""
    from ...validation import finite_nonnegative

    return finite_nonnegative(value, name)
