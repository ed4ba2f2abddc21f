"""Fast mass-spring (Liu, Bargteil, O'Brien, Kavan 2013): implicit Euler by local/global iterations.

Implicit Euler minimises ``g(x) = 1/2 ||x - y||_M^2 + h^2 E(x)`` with ``y = x_n + h v_n``. Each
spring energy is written ``1/2 k min_{|d| = r} |x_i - x_j - d|^2``; alternating

* local step: ``d_s = r_s (x_i - x_j) / |x_i - x_j|`` for every spring (vectorised), and
* global step: ``(M + h^2 L) x = M y + h^2 (J d + f_ext)``,

decreases ``g`` monotonically. Since ``J d + f_ext = f(x) + L x`` at the current iterate (``f``:
every declared force), the global step is ``(M + h^2 L) x+ = M y + h^2 (f(x) + L x)``; forces
that depend on velocity see ``(x - x_n) / h`` (explicitly, per iteration).

``L = system.spring_laplacian()`` is ``n x n``: the coordinates decouple, so one ``n x n``
factorisation serves all ``d`` coordinates (``d`` right-hand sides per solve). The matrix depends
only on ``dt``, masses, stiffnesses, topology and the pinned set, so it is factorised once (through
``femkit.solvers``' direct factorisation) and kept in ``ctx.cache`` under a key built from those;
``ctx.stats["factorizations"]`` counts factorisations. Pinned nodes are eliminated: their rows
are dropped and their (fixed) positions move to the right-hand side.

``iterations`` local/global sweeps per step (Liu et al.: 10); with ``tol`` set, the sweeps stop
early when ``||x+ - x||_inf <= tol * L_box``. Iterated to convergence this is implicit Euler
(``newton``); with few iterations it is an approximation that damps high frequencies. Order 1,
unconditionally stable.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from .base import Integrator, StepContext, StepperState, factorize_linear, restrict
from .registry import INTEGRATORS


def _digest(a) -> int:
    a = np.ascontiguousarray(np.asarray(a))
    return hash((a.dtype.str, a.shape, a.tobytes()))


@INTEGRATORS.register("fast_mass_spring")
@dataclass(frozen=True)
class FastMassSpring(Integrator):
    iterations: int = 10
    tol: float | None = None

    name = "fast_mass_spring"
    order = 1
    implicit = True
    symplectic = False

    def __post_init__(self):
        if int(self.iterations) < 1:
            raise InputError(f"fast_mass_spring: iterations must be >= 1, got {self.iterations}")

    def _factor(self, system, dt: float, ctx: StepContext):
        key = (float(dt), _digest(system.mass), _digest(system.k), _digest(system.springs),
               _digest(system.pinned), system.n)
        cached = ctx.cache.get("fast_mass_spring")
        if cached is not None and cached[0] == key:
            return cached[1]
        free_nodes = np.flatnonzero(~system.pinned)
        pinned_nodes = np.flatnonzero(system.pinned)
        L = system.spring_laplacian().tocsr()
        import scipy.sparse as sp

        A = (sp.diags(np.asarray(system.mass, dtype=float)) + (dt * dt) * L).tocsr()
        A_fp = A[free_nodes][:, pinned_nodes].tocsr()
        entry = {
            "factor": factorize_linear(restrict(A, free_nodes), ctx),
            "L": L,
            "A_fp": A_fp,
            "free": free_nodes,
            "pinned": pinned_nodes,
        }
        ctx.cache["fast_mass_spring"] = (key, entry)
        return entry

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        h = dt
        fac = self._factor(system, h, ctx)
        free, pinned, L = fac["free"], fac["pinned"], fac["L"]
        m = np.asarray(system.mass, dtype=float)[:, None]
        xn = state.x
        y = xn + h * state.v
        x = y.copy()
        x[pinned] = xn[pinned]
        rhs_pinned = fac["A_fp"] @ xn[pinned] if pinned.size else 0.0
        length = float(np.linalg.norm(np.ptp(xn, axis=0))) or 1.0
        t_new = state.t + h
        for _ in range(int(self.iterations)):
            f = system.force(x, (x - xn) / h, t_new)
            rhs = m * y + (h * h) * (f + L @ x)
            x_free = fac["factor"].solve(rhs[free] - rhs_pinned)
            change = np.abs(x_free - x[free]).max(initial=0.0)
            x = x.copy()
            x[free] = x_free
            if self.tol is not None and change <= self.tol * length:
                break
        return StepperState(x, (x - xn) / h, t_new)
