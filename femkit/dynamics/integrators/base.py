"""Shared pieces of every time integrator: the step context, the stepper state, the base class.

Design
------
An integrator is a small frozen dataclass (its *options* are its fields) with two methods:

* ``start(system, x, v, t, dt, ctx) -> StepperState`` builds the state the integrator needs
  (multistep methods keep the previous position or a half-step velocity in ``state.aux``);
* ``step(system, state, dt, ctx) -> StepperState`` advances by one step and returns a *new*
  state (the input is never modified).

``state.x`` / ``state.v`` are always the positions and velocities at ``state.t`` (node-major
``(n, d)`` arrays), so energies and outputs read the same fields for every method.
Per-run caches (a factorised matrix, counters) live in :class:`StepContext`, never in the
integrator object, so one integrator instance can drive several runs.

Linear solves of the implicit methods go through :func:`solve_linear` / :func:`factorize_linear`,
which call :mod:`femkit.solvers` with the solver named in the context and restrict every system
to ``system.free_dofs`` (pinned dofs are eliminated).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import InputError, SolverError

__all__ = [
    "StepContext",
    "StepperState",
    "Integrator",
    "solve_linear",
    "factorize_linear",
    "restrict",
]


@dataclass
class StepContext:
    """Linear-solver choice and per-run caches handed to every ``step``.

    Parameters
    ----------
    solver : str
        Name of a :mod:`femkit.solvers` method (``"direct"``, ``"cg"``, ``"pcg"``, ``"jacobi"``).
    preconditioner : str
        Preconditioner name for ``pcg`` (``"none"``, ``"jacobi"``, ``"ic0"``, ``"amg"``).
    rtol, atol, maxiter : float, float, int or None
        Stopping rule of iterative solvers.
    options : dict
        Extra keyword options passed to ``femkit.solvers.solve``.
    cache : dict
        Per-run caches (e.g. the fast mass-spring factorisation); filled by integrators.
    stats : dict
        Counters integrators report (``factorizations``, ``linear_solves``,
        ``newton_iterations`` list, ``linear_iterations``).
    """

    solver: str = "direct"
    preconditioner: str = "none"
    rtol: float = 1e-10
    atol: float = 0.0
    maxiter: int | None = None
    options: dict = field(default_factory=dict)
    cache: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)

    def count(self, key: str, n: int = 1) -> None:
        """Add ``n`` to counter ``key`` of :attr:`stats`."""
        self.stats[key] = self.stats.get(key, 0) + n


@dataclass
class StepperState:
    """Positions ``x`` and velocities ``v`` (``(n, d)``) at time ``t``, plus method extras in ``aux``."""

    x: np.ndarray
    v: np.ndarray
    t: float
    aux: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Integrator:
    """Base class of all integrators (see the module docstring for the protocol).

    Class attributes every subclass sets: ``name``, ``order`` (global order of accuracy of the
    positions), ``implicit``, ``symplectic`` and ``stability_bound`` (the largest ``h * omega``
    for which the undamped oscillator stays bounded, ``inf`` for unconditionally stable methods;
    the critical step is ``stability_bound / omega_max``).
    """

    name = "integrator"
    order = 1
    implicit = False
    symplectic = False
    stability_bound = math.inf

    def start(self, system, x, v, t: float, dt: float, ctx: StepContext) -> StepperState:
        """Initial state: copies of ``x``, ``v`` with pinned velocities zeroed."""
        x = np.array(x, dtype=float, copy=True)
        v = np.array(v, dtype=float, copy=True)
        if x.shape != (system.n, system.dim) or v.shape != x.shape:
            raise InputError(
                f"{self.name}: x and v must have shape {(system.n, system.dim)}, "
                f"got {x.shape} and {v.shape}"
            )
        v[system.pinned] = 0.0
        return StepperState(x, v, float(t))

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        raise NotImplementedError

    def dahlquist_amplification(self, z: complex) -> complex:
        """Amplification factor ``R(z)`` of the method on ``y' = lambda y``, ``z = h lambda``.

        Partitioned (symplectic) methods have no single-equation form and raise
        ``NotImplementedError``.
        """
        raise NotImplementedError(f"{self.name} has no first-order (Dahlquist) form")

    def describe(self) -> dict:
        """JSON-ready facts: name, order, implicit, symplectic, stability bound and options."""
        opts = {k: v for k, v in self.__dict__.items()}
        bound = self.stability_bound
        return {
            "name": self.name,
            "order": self.order,
            "implicit": self.implicit,
            "symplectic": self.symplectic,
            "stability_bound": None if math.isinf(bound) else float(bound),
            "options": opts,
        }


# ----------------------------------------------------------------------------- linear algebra
def restrict(A, free):
    """``A[free][:, free]`` for a sparse matrix (CSR out)."""
    A = A.tocsr()
    return A[free][:, free].tocsr()


def solve_linear(A, b: np.ndarray, ctx: StepContext, x0: np.ndarray | None = None) -> np.ndarray:
    """Solve ``A x = b`` with the method named in ``ctx`` through ``femkit.solvers.solve``.

    Raises :class:`~femkit.errors.SolverError` when an iterative method does not converge:
    an implicit step never continues from an unconverged solve.
    """
    from ...solvers import solve as _solve  # lazy: keeps ``import femkit.dynamics`` light

    ctx.count("linear_solves")
    res = _solve(A, b, x0, method=ctx.solver, preconditioner=ctx.preconditioner,
                 rtol=ctx.rtol, atol=ctx.atol, maxiter=ctx.maxiter, **ctx.options)
    ctx.count("linear_iterations", int(res.iterations))
    if not res.converged:
        raise SolverError(
            f"linear solve ({ctx.solver}/{ctx.preconditioner}) did not converge: {res.reason}; "
            f"relative residual {res.relative_residual:.3e} after {res.iterations} iterations"
        )
    return np.asarray(res.x, dtype=float)


def factorize_linear(A, ctx: StepContext):
    """Factorise a sparse SPD matrix once for repeated solves; returns an object with ``.solve(b)``.

    ``b`` may be ``(n,)`` or ``(n, k)`` (several right-hand sides in one call).
    """
    from ...solvers import factorize

    ctx.count("factorizations")
    return factorize(A)
