"""What every method-of-lines scheme shares: the state :class:`MolState` and the base classes
:class:`HeatScheme` (``M u' + K u = F``) and :class:`WaveScheme` (``M u'' + K u = F``).

A scheme is a frozen dataclass (its options are its fields) with ``start`` (the state at
``t0``) and ``step`` (a new state ``dt`` later; the input is not modified). Its traits are
class attributes: ``order`` (global order in time), ``explicit``, ``stability_bound`` (the
largest ``dt * lambda_max`` for a first-order scheme, ``dt * omega_max`` for a second-order one,
``omega_max = sqrt(lambda_max)``, ``lambda_max`` the largest eigenvalue of ``M^-1 K`` on the
free nodes; ``inf``: unconditionally stable) and ``embedded`` (the step also returns an error
estimate, so adaptive steps can use it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["MolState", "HeatScheme", "WaveScheme"]


@dataclass
class MolState:
    """Nodal values ``u`` (and ``v = u'``, ``a = u''`` of a second-order system) at ``t``;
    ``aux`` holds a scheme's extras (BDF2's previous value, an error estimate)."""

    t: float
    u: np.ndarray
    v: np.ndarray | None = None
    a: np.ndarray | None = None
    aux: dict = field(default_factory=dict)


class _Traits:
    name = ""
    order = 1
    explicit = False
    stability_bound = math.inf
    embedded = False

    def validate(self) -> None:
        """Raise :class:`~femkit.errors.InputError` on invalid options (none by default)."""

    def critical_step(self, lam_max: float) -> float:
        """The largest stable step on a system whose ``M^-1 K`` has largest eigenvalue
        ``lam_max`` (``inf`` when unconditionally stable)."""
        raise NotImplementedError

    def describe(self) -> dict:
        """JSON-ready facts: name, order, explicit, stability bound and options."""
        bound = self.stability_bound
        return {"name": self.name, "order": self.order, "explicit": self.explicit,
                "stability_bound": None if math.isinf(bound) else float(bound),
                "options": dict(self.__dict__)}


class HeatScheme(_Traits):
    """First-order system ``M u' + K u = F(t)``: ``stability_bound`` bounds ``dt * lambda_max``."""

    def critical_step(self, lam_max: float) -> float:
        if math.isinf(self.stability_bound) or lam_max <= 0.0:
            return math.inf
        return self.stability_bound / lam_max

    def start(self, system, u0: np.ndarray, t0: float, dt: float) -> MolState:
        """The state at ``t0`` (``u0`` with the Dirichlet values of ``t0`` in place)."""
        u = np.array(u0, dtype=np.float64, copy=True)
        u[system.fixed] = system.g(t0)
        return MolState(float(t0), u)

    def step(self, system, state: MolState, dt: float) -> MolState:
        raise NotImplementedError


class WaveScheme(_Traits):
    """Second-order system ``M u'' + K u = F(t)``: ``stability_bound`` bounds ``dt * omega_max``."""

    def critical_step(self, lam_max: float) -> float:
        if math.isinf(self.stability_bound) or lam_max <= 0.0:
            return math.inf
        return self.stability_bound / math.sqrt(lam_max)

    def start(self, system, u0: np.ndarray, v0: np.ndarray, t0: float, dt: float) -> MolState:
        """The state at ``t0`` with the acceleration ``a0`` of ``M a0 = F - K u0`` on the free
        rows (the boundary's acceleration from the Dirichlet data by finite differences); ``v0``
        is taken as given on every node, so on the Dirichlet nodes it should be ``g'(t0)``."""
        u = np.array(u0, dtype=np.float64, copy=True)
        v = np.array(v0, dtype=np.float64, copy=True)
        u[system.fixed] = system.g(t0)
        system.t0 = float(t0)  # v0 is the caller's on every node (g'(t0) on the Dirichlet nodes)
        a = acceleration(system, u, t0, dt)
        return MolState(float(t0), u, v, a)

    def step(self, system, state: MolState, dt: float) -> MolState:
        raise NotImplementedError


def boundary_acceleration(system, t: float, dt: float) -> np.ndarray:
    """``g''(t)`` at the Dirichlet nodes by a second difference of step ``dt`` (central, or
    forward at the first time); zeros for constant data."""
    if system.boundary_constant or system.fixed.size == 0:
        return np.zeros(system.fixed.size)
    t0 = getattr(system, "t0", t)
    if t - dt < t0 - 1e-14 * max(1.0, abs(t0)):
        return (system.g(t + 2 * dt) - 2 * system.g(t + dt) + system.g(t)) / dt ** 2
    return (system.g(t + dt) - 2 * system.g(t) + system.g(t - dt)) / dt ** 2


def acceleration(system, u: np.ndarray, t: float, dt: float) -> np.ndarray:
    """``a`` with ``M a = F(t) - K u`` on the free rows and ``g''(t)`` on the Dirichlet nodes."""
    rhs = system.F(t)[system.free] - system.K_f @ u if system.has_load else -(system.K_f @ u)
    return system.solve(1.0, 0.0, rhs, t, values=boundary_acceleration(system, t, dt))


def rate(system, u: np.ndarray, t: float, dt: float) -> np.ndarray:
    """``u'`` with ``M u' = F(t) - K u`` on the free rows and ``(g(t + dt) - g(t)) / dt`` on the
    Dirichlet nodes (zeros for constant data)."""
    rhs = system.F(t)[system.free] - system.K_f @ u if system.has_load else -(system.K_f @ u)
    values = (np.zeros(system.fixed.size) if system.boundary_constant or system.fixed.size == 0
              else (system.g(t + dt) - system.g(t)) / dt)
    return system.solve(1.0, 0.0, rhs, t, values=values)
