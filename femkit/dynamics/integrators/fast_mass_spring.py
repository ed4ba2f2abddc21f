"""Fast mass-spring (Liu, Bargteil, O'Brien, Kavan 2013): implicit Euler by local/global iterations.

Implicit Euler minimises ``g(x) = 1/2 ||x - y||_M^2 + h^2 E(x)`` with ``y = x_n + h v_n``. Each
spring energy is written ``1/2 k min_{|d| = r} |x_i - x_j - d|^2``; alternating

* local step: ``d_s = r_s (x_i - x_j) / |x_i - x_j|`` for every spring (vectorised), and
* global step: ``(M + h^2 L) x = M y + h^2 (J d + f_ext)``,

decreases ``g`` monotonically. ``f_ext`` is every declared force except the Hooke springs:
forces flagged constant (gravity, :meth:`~femkit.dynamics.system.MassSpringSystem.constant_force`)
are evaluated once per step; dashpots and the other forces
(:meth:`~femkit.dynamics.system.MassSpringSystem.variable_force`) are evaluated per iteration,
with velocity ``(x - x_n) / h``. Without such forces an iteration costs two sparse
products over the springs and one triangular-solve pass.

Damping is split, not lagged: a constant ``n x n`` matrix ``B`` (viscous coefficients and
Rayleigh ``alpha m`` on the diagonal, the dashpot coefficients' Laplacian
``sum_s c_s A_s A_s^T`` and Rayleigh's ``beta L``) joins the factorised matrix, and the global
step solves ``(M + h^2 L + h B) x = M y + h^2 (J d + f_ext + f_var(x_k)) + h B x_k``. At a fixed
point the ``h B`` terms cancel, so the converged step is still implicit Euler with the true
(position-dependent) damping; but the iteration no longer amplifies the damping force: the
remainder ``h (B - C(x))`` is zero for viscous and Rayleigh-mass damping and between 0 and
``h B`` for dashpots (``c (I - u u^T)``) and stretched springs' Rayleigh-stiffness part. (Treating
the damping explicitly inside the iteration diverged once ``h c / m > 1``.)

Penalty contact stays explicit inside the iteration (its stiffness changes with the active
set, the matrix is factorised once); the iteration then diverges at a penetrating node when
``h^2 k_c > m_i + h^2 L_ii``. :meth:`FastMassSpring.start` warns
(:class:`~femkit.errors.StabilityWarning`) when a declared contact is that stiff: use
``newton`` or ``implicit_euler`` there.

Implementation
--------------
``L = system.spring_laplacian()`` is ``n x n``: the coordinates decouple, so one ``n x n``
factorisation (``femkit.solvers.factorize``: SuperLU, symmetric mode with the ``MMD_AT_PLUS_A``
ordering for this SPD matrix) serves all ``d`` coordinates, solved as one ``(n_free, d)``
right-hand-side block in Fortran order (one pass through the factors). Pinned nodes are
eliminated: their rows are dropped and their fixed positions move to the right-hand side; nodes
held in some components only (rollers) are eliminated per coordinate
(:class:`~.component_pins.ComponentSolve`, one more factorisation per distinct held set).
The local step and ``J d`` are two precomputed sparse matrices: ``G`` (``s x n_free``, the
spring differences ``x_j - x_i``) and ``G^T diag(k r)``, so ``J d = G^T diag(k r) (dx / |dx|)``
(lengths floored at ``system.length_floor``).

Cache: the matrix depends only on ``dt``, masses, stiffnesses, rest lengths (in ``J``),
damping coefficients, topology and the pinned set, so the factor and the spring operators are built once and kept in
``ctx.cache["fast_mass_spring"]``. The cache key is ``dt`` and the *identity* of the system and
of its ``mass``, ``k``, ``rest``, ``damping``, ``springs``, ``pinned`` and ``forces`` attributes (the cache
holds references, so identities cannot be recycled): assigning a new array invalidates it,
modifying one of those arrays in place does not (clear ``ctx.cache`` then). No array is hashed
per step. ``ctx.stats["factorizations"]`` counts factorisations, ``ctx.stats["linear_solves"]``
the global solves (one per iteration, all coordinates at once).

With the ``cholesky`` solver the matrix is factorised by CHOLMOD
(:func:`femkit.solvers.factorize_spd`) and the local step and ``J d`` are one compiled pass over
the springs (:func:`femkit.dynamics.kernels.spring_kernels.local_global_rhs`), writing the
right-hand side of the free nodes directly (the pinned nodes' positions read in place).

Chebyshev acceleration (``chebyshev=True``; Wang 2015, "A Chebyshev semi-iterative approach for
accelerating projective and position-based dynamics", ACM TOG 34(6)): after ``chebyshev_delay``
plain sweeps each iterate is extrapolated, ``x_{k+1} = omega_{k+1} (x^_{k+1} - x_{k-1}) + x_{k-1}``
with ``omega = 2 / (2 - rho^2)`` at the first accelerated sweep and ``4 / (4 - rho^2 omega)``
after. The spectral radius ``rho`` of the local/global iteration is estimated once per run
(``chebyshev_warmup`` plain sweeps of the first step on a scratch copy, the ratio of successive
iterate differences; ``ctx.stats["chebyshev_rho"]``), or given as ``chebyshev_rho``. A fixed
point of the accelerated iteration is still the implicit Euler step.

``iterations`` local/global sweeps per step (Liu et al.: 10); with ``tol`` set, the sweeps stop
early when ``||x+ - x||_inf <= tol * L_box``. Iterated to convergence this is implicit Euler
(``newton``); with few iterations it is an approximation that damps high frequencies. Order 1,
unconditionally stable.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...solvers.operators import restrict
from .base import Integrator, StepContext, StepperState, box_length, check_iteration_options
from .component_pins import ComponentSolve
from .registry import register

_KEY_ATTRS = ("mass", "k", "rest", "damping", "springs", "pinned", "pinned_dofs", "forces")


def _cache_key(system, dt: float) -> tuple:
    return (float(dt), system) + tuple(getattr(system, a) for a in _KEY_ATTRS)


def _same_key(a: tuple, b: tuple) -> bool:
    return a[0] == b[0] and len(a) == len(b) and all(p is q for p, q in zip(a[1:], b[1:]))


def damping_split(system, L=None):
    """The constant ``n x n`` damping matrix ``B`` of the split (module docstring), or ``None``
    when nothing damps: per-node viscous coefficients (largest diagonal entry of each node's
    block of the declared forces' ``D``) and Rayleigh ``alpha m`` on the diagonal, plus the
    Laplacian of the dashpot coefficients and ``beta`` times the spring Laplacian ``L``."""
    import scipy.sparse as sp

    from ..forces.jacobian import SpringPattern

    n, d = system.n, system.dim
    alpha, beta = system.rayleigh
    diag = alpha * np.asarray(system.mass, dtype=float)
    for f in system.forces:
        D = None if f.constant else f.damping(system.x0)
        if D is not None:
            diag = diag + np.abs(D.diagonal()).reshape(n, d).max(axis=1)
    parts = []
    if np.any(diag > 0.0):
        parts.append(sp.diags(diag))
    if system.n_springs and np.any(np.asarray(system.damping) > 0.0):
        pat = SpringPattern(n, 1, system.springs[:, 0], system.springs[:, 1])
        parts.append(pat.assemble(np.asarray(system.damping, dtype=float).reshape(-1, 1, 1)))
    if beta > 0.0 and system.n_springs:
        parts.append(beta * (system.spring_laplacian() if L is None else L))
    if not parts:
        return None
    B = parts[0]
    for P in parts[1:]:
        B = B + P
    return B.tocsr()


def _spring_rows(system, free: np.ndarray) -> tuple:
    """The free-row numbers of every spring's two ends (``-1`` for a pinned end)."""
    free_of = np.full(system.n, -1, dtype=np.int64)
    free_of[free] = np.arange(len(free))
    return free_of[system._i], free_of[system._j]


@dataclass
class _Operators:
    """Everything a fast mass-spring step reuses while the cache key holds."""

    factor: object              # ComponentSolve: per-coordinate elimination of rollers
    free: np.ndarray            # nodes free in some component
    pinned: np.ndarray          # nodes held in every component
    m_free: np.ndarray          # (nf, 1)
    G_free: object              # s x nf: x_j - x_i on free nodes
    G_pin: object               # s x np: the pinned nodes' part of x_j - x_i
    Jkr: object                 # nf x s: G_free^T diag(k r)
    A_fp: object                # nf x np block of M + h^2 L
    f_const: np.ndarray         # (nf, d) constant forces on the free nodes
    floor: float
    B_free: object = None       # nf x n rows of the damping split h B (None: no damping)
    spring_rows: tuple = ()     # (fi, fj): free rows of every spring's ends, -1 if pinned


@register("fast_mass_spring")
@dataclass(frozen=True)
class FastMassSpring(Integrator):
    iterations: int = 10
    tol: float | None = None
    chebyshev: bool = False
    chebyshev_rho: float | None = None
    chebyshev_delay: int = 2
    chebyshev_warmup: int = 10

    order = 1
    implicit = True
    symplectic = False
    #: one kept factorisation: ~2 step-equivalents for its 10 cheap local/global sweeps
    solves_per_step = 2.0
    work_precision = {"fast_mass_spring": ("fast mass-spring", "iterations", {}),
                      "chebyshev": ("Chebyshev fast mass-spring", "iterations", {"chebyshev": True})}

    def __post_init__(self):
        check_iteration_options(self.name, self.iterations, self.tol, option="iterations")
        rho = self.chebyshev_rho
        if rho is not None and not (0.0 <= rho < 1.0):
            raise InputError(f"{self.name}: chebyshev_rho must lie in [0, 1), got {rho!r}")
        if int(self.chebyshev_delay) < 1 or int(self.chebyshev_warmup) < 3:
            raise InputError(f"{self.name}: need chebyshev_delay >= 1 and chebyshev_warmup >= 3, got "
                             f"{self.chebyshev_delay!r}, {self.chebyshev_warmup!r}")

    def start(self, system, x, v, t: float, dt: float, ctx: StepContext) -> StepperState:
        """The usual start, plus a :class:`~femkit.errors.StabilityWarning` when a declared
        penalty contact is too stiff for the local/global iteration (module docstring)."""
        state = super().start(system, x, v, t, dt, ctx)
        kc = max((float(f.stiffness_value) for f in system.forces
                  if getattr(f, "kind", None) == "contact"), default=0.0)
        if kc > 0.0 and np.any(~system.pinned):
            free = ~system.pinned
            lap = system.spring_laplacian().diagonal()
            ratio = float(np.max(dt * dt * kc / (system.mass[free] + dt * dt * lap[free])))
            if ratio > 1.0:
                import warnings

                from ...errors import StabilityWarning

                warnings.warn(StabilityWarning(
                    f"fast_mass_spring: penalty contact stiffness {kc:.4g} is explicit inside the "
                    f"local/global iteration and too stiff for dt = {dt:.4g}: "
                    f"h^2 k_c / (m + h^2 L_ii) = {ratio:.3g} > 1, so the iteration diverges once "
                    "a particle penetrates; use newton or implicit_euler (or a smaller dt)"),
                    stacklevel=2)
        return state

    def _operators(self, system, dt: float, ctx: StepContext) -> _Operators:
        key = _cache_key(system, dt)
        cached = ctx.cache.get("fast_mass_spring")
        if cached is not None and _same_key(cached[0], key):
            return cached[1]
        import scipy.sparse as sp

        free = np.flatnonzero(~system.pinned)
        pinned = np.flatnonzero(system.pinned)
        mass = np.asarray(system.mass, dtype=float)
        L = system.spring_laplacian()
        A = sp.diags(mass) + (dt * dt) * L
        B = damping_split(system, L)
        if B is not None:
            A = A + dt * B
        A = A.tocsr()
        G = system.difference_operators[0]
        G_free = G[:, free].tocsr()
        ops = _Operators(
            factor=ComponentSolve(restrict(A, free), system.pinned_dofs[free],
                                  ctx.session.factorize),
            free=free,
            pinned=pinned,
            m_free=mass[free][:, None],
            G_free=G_free,
            G_pin=G[:, pinned].tocsr(),
            Jkr=(G_free.T @ sp.diags(system.k * system.rest)).tocsr(),
            A_fp=A[free][:, pinned].tocsr(),
            f_const=system.constant_force()[free],
            floor=float(system.length_floor),
            B_free=None if B is None else (dt * B.tocsr()[free]).tocsr(),
            spring_rows=_spring_rows(system, free),
        )
        ctx.cache["fast_mass_spring"] = (key, ops)
        return ops

    def _sweep(self, system, ops: _Operators, x, xn, h: float, t_new: float, const, dx_pin,
               ctx: StepContext):
        """One local/global iteration as a function ``x_free -> x_free'`` (``x``: a full
        ``(n, d)`` work array whose pinned rows hold the fixed positions)."""
        free = ops.free
        y_held = x[free]                             # the rollers' held components (fixed)
        variable = system.has_variable_forces
        compiled = ctx.linear_solver.method == "cholesky"
        if compiled:
            from ..kernels.spring_kernels import local_global_rhs

            i, j = system._i, system._j
            kr = system.k * system.rest
            fi, fj = ops.spring_rows

        def sweep(x_free):
            if compiled:  # local step and J d in one compiled pass
                rhs = np.empty_like(const)
                local_global_rhs(x_free, x, i, j, fi, fj, kr, ops.floor, h * h, const, rhs)
                if variable:
                    x[free] = x_free
                    rhs += (h * h) * system.variable_force(x, (x - xn) / h, t_new)[free]
            else:
                dx = ops.G_free @ x_free            # (s, d): x_j - x_i
                if dx_pin is not None:
                    dx += dx_pin
                ln = np.sqrt(np.einsum("sd,sd->s", dx, dx))
                np.maximum(ln, ops.floor, out=ln)
                dx /= ln[:, None]
                rhs = ops.Jkr @ dx                  # J d, (nf, d)
                if variable:
                    x[free] = x_free
                    rhs += system.variable_force(x, (x - xn) / h, t_new)[free]
                rhs *= h * h
                rhs += const
            if ops.B_free is not None:
                x[free] = x_free
                rhs += ops.B_free @ x                # h B x_k (the damping split)
            ctx.count("linear_solves")               # one global solve (all d columns) per sweep
            return ops.factor.solve(rhs if compiled else np.asfortranarray(rhs), y_held)

        return sweep

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        h = dt
        ops = self._operators(system, h, ctx)
        free, pinned = ops.free, ops.pinned
        xn = state.x
        t_new = state.t + h
        x = xn + h * state.v                    # y; pinned rows back to x_n below
        x[pinned] = xn[pinned]
        y_free = x[free]
        const = ops.m_free * y_free + (h * h) * ops.f_const
        dx_pin = None
        if pinned.size:
            x_pin = xn[pinned]
            const -= ops.A_fp @ x_pin
            dx_pin = ops.G_pin @ x_pin
        sweep = self._sweep(system, ops, x, xn, h, t_new, const, dx_pin, ctx)
        length = box_length(xn) if self.tol is not None else 1.0
        rho = self._rho(sweep, y_free, ctx) if self.chebyshev else 0.0
        x_prev = x_free = y_free
        omega = 1.0
        for k in range(int(self.iterations)):
            x_hat = sweep(x_free)
            if self.chebyshev and k >= self.chebyshev_delay:
                # Wang (2015), eq. (12): omega_{S+1} = 2 / (2 - rho^2), then 4 / (4 - rho^2 omega)
                omega = 2.0 / (2.0 - rho * rho) if k == self.chebyshev_delay \
                    else 4.0 / (4.0 - rho * rho * omega)
                x_hat = omega * (x_hat - x_prev) + x_prev
            x_prev, x_new = x_free, x_hat
            if self.tol is not None:
                change = np.abs(x_new - x_free).max(initial=0.0)
                x_free = x_new
                if change <= self.tol * length:
                    break
            else:
                x_free = x_new
        x[free] = x_free
        return StepperState(x, (x - xn) / h, t_new)

    def _rho(self, sweep, y_free, ctx: StepContext) -> float:
        """The Chebyshev spectral radius: ``chebyshev_rho`` when given, else estimated once per
        run (kept in ``ctx.cache``) from ``chebyshev_warmup`` plain iterations of the first step
        on a scratch copy: the ratio ``||x_{k+1} - x_k|| / ||x_k - x_{k-1}||`` of successive
        differences tends to the spectral radius of the local/global iteration (its
        dominant eigenvalue); the median of the last three ratios, capped at 0.999."""
        if self.chebyshev_rho is not None:
            return float(self.chebyshev_rho)
        kept = ctx.cache.get("chebyshev_rho")
        if kept is not None:
            return kept
        diffs = []
        xk = y_free
        for _ in range(int(self.chebyshev_warmup)):
            xk1 = sweep(xk)
            diffs.append(float(np.linalg.norm(xk1 - xk)))
            xk = xk1
        d = np.asarray(diffs)
        ok = d[:-1] > 1e-300
        ratios = d[1:][ok] / d[:-1][ok]
        rho = float(min(np.median(ratios[-3:]), 0.999)) if ratios.size else 0.0
        ctx.cache["chebyshev_rho"] = rho
        ctx.stats["chebyshev_rho"] = rho
        return rho
