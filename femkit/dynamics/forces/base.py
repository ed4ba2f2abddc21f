"""The protocol every declared force follows (gravity, viscous, Rayleigh, contacts).

A force object is small and data-like; :class:`~femkit.dynamics.system.MassSpringSystem`
calls :meth:`Force.bind` once at construction (precompute per-system arrays) and then,
per evaluation, only the methods below. Every method has a "nothing" default, so a
force implements only what it contributes.

The step protocol of the minimising integrators (``newton``): :meth:`Force.begin_step`,
:meth:`Force.step_bound` (a line search never steps past it), :meth:`Force.end_iteration`,
:meth:`Force.relag` and :meth:`Force.end_step`, no-ops here; barrier contact
(:mod:`.barrier`) uses them and declares ``requires_bounded_steps = True``, which every
integrator without ``keeps_contact`` refuses.

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
    #: Only an integrator that bounds every step by :meth:`step_bound` keeps this force's
    #: guarantee (``Integrator.keeps_contact``); the others refuse it.
    requires_bounded_steps: bool = False

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

    def begin_step(self, x: np.ndarray, h: float, objective_gradient, t: float = 0.0) -> None:
        """A minimising step from time ``t`` of length ``h`` starts from ``x``
        (``objective_gradient(x_flat)``: the step objective's gradient)."""

    def advance(self, x: np.ndarray) -> bool:
        """After a step's solve at ``x``: True when this force's prescribed motion moved on
        (a new objective: solve again), False when it is where the step ends."""
        return False

    def step_bound(self, x: np.ndarray, x_try: np.ndarray) -> float:
        """The largest admissible fraction of the move ``x -> x_try`` (1: all of it)."""
        return 1.0

    def end_iteration(self, x: np.ndarray) -> bool:
        """After an iteration at ``x``; True when this force's energy changed (re-evaluate)."""
        return False

    def relag(self, x_start: np.ndarray, x: np.ndarray, h: float) -> bool:
        """Whether the step from ``x_start``, solved to ``x``, is to be solved again with
        lagged quantities renewed at ``x``."""
        return False

    def end_step(self) -> None:
        """The step is over."""


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
