"""The semi-discrete linear system the method-of-lines schemes step: :class:`LinearSystem`.

``M u' + K u = F(t)`` (heat) or ``M u'' + K u = F(t)`` (wave) on all ``n`` nodes, with the
Dirichlet nodes ``fixed`` held at ``g(t)``. A scheme forms its full-size right-hand side ``r``
and a matrix ``A = a M + b K``; :meth:`LinearSystem.solve` solves the free rows
``A_ff x_f = r_f - A_fb g`` with the boundary values ``g`` in place (so time-dependent
Dirichlet data enter every scheme the way its own discretisation of ``M u'`` says, with no
separate ``g'``). All solves go through one :class:`~femkit.solvers.session.LinearSession`
(its counters are the system's ``stats``). Each distinct ``A`` is factorised once and kept for
the whole run (:meth:`LinearSession.factorize`; SuperLU in symmetric mode, or the sparse
Cholesky engines) when the linear solver is ``direct`` or ``cholesky``; with an iterative solver
its preconditioner (AMG hierarchy, IC(0) factor) is built once and kept the same way
(:meth:`LinearSession.solve_kept`, ``stats["preconditioner_setups"]``), and each step's solve
starts from the quadratic extrapolation ``3 (x_n - x_{n-1}) + x_{n-2}`` of that matrix's last three
solutions. A
new ``dt`` (adaptive steps) is a new ``A``: factorised or set up afresh. Another backend named in the solver spec
(``petsc``: :data:`femkit.solvers.registry.BACKENDS`) solves every step by its own KSP,
warm-started, nothing kept; the heat and wave kinds run PETSc through their distributed
system instead (``femkit.case.transient.distributed``: one KSP kept per matrix, any number of
ranks). A lumped (diagonal) ``M`` alone is inverted by a division.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp

from ...errors import InputError
from ...solvers.spec import SolverSpec

__all__ = ["LinearSystem", "ConstrainedOperator", "KEPT_FACTOR_METHODS", "DIRECT_LIMIT",
           "IC0_LIMIT", "step_solver", "stiffness_ratio"]

#: Solver methods whose factor is kept across steps; any other is an iterative solve per step.
KEPT_FACTOR_METHODS = frozenset({"direct", "cholesky"})

#: The most free unknowns, by dimension, for which the default step solver is a kept SuperLU
#: factor; above it, PCG with a kept IC(0) or AMG preconditioner (:data:`IC0_LIMIT`), warm-started. Measured with
#: ``benchmarks/bench_heat.py --solvers`` (docs/heat_wave.md: figures and why).
DIRECT_LIMIT = {2: 100_000, 3: 30_000}

#: The preconditioner of the large systems by the stiffness of the step matrix ``a M + b K``,
#: ``r = b median(K_ii / M_ii)`` (about ``8 dt / h^2`` for a heat step on a P1 triangle grid):
#: IC(0) up to :data:`IC0_LIMIT` (its iterations grow as ``sqrt(r)``: 3 at ``r ~ 3``, 11 at
#: ``r = 200``, 58 at ``r = 2000``; cheap per iteration), Ruge-Stueben AMG above (3-5 iterations
#: whatever ``r``, each about 4 IC(0) iterations' cost in 2D and 20 in 3D).
IC0_LIMIT = 1000.0


def step_solver(dim: int, n_free: int, spec: SolverSpec | None = None,
                stiffness: float = 0.0) -> SolverSpec:
    """The default linear solver of the implicit steps of a system of ``n_free`` unknowns on a
    ``dim``-dimensional mesh whose step matrix has stiffness ratio ``stiffness``
    (:data:`IC0_LIMIT`): ``spec`` (default ``direct``) up to :data:`DIRECT_LIMIT`, else
    ``spec`` turned into PCG with a kept IC(0) (reverse Cuthill-McKee ordered;
    ``stiffness <= IC0_LIMIT``) or Ruge-Stueben AMG preconditioner, its tolerances kept.

    >>> step_solver(2, 50_000).method, step_solver(3, 200_000, stiffness=5.0).preconditioner
    ('direct', 'ic0')
    >>> step_solver(2, 250_000, stiffness=2000.0).preconditioner
    'amg_rs'
    """
    spec = SolverSpec("direct") if spec is None else spec
    if n_free <= DIRECT_LIMIT.get(dim, DIRECT_LIMIT[3]):
        return spec
    if stiffness <= IC0_LIMIT:   # RCM: 19 iterations instead of 28 on a refined gmsh mesh
        return spec.replace(method="pcg", preconditioner="ic0",
                            preconditioner_options={"ordering": "rcm"})
    return spec.replace(method="pcg", preconditioner="amg_rs", preconditioner_options={})


def stiffness_ratio(M, K, free: np.ndarray, b: float) -> float:
    """``b median(K_ii / M_ii)`` over the free rows: how far ``M + b K`` is from the mass
    matrix (:data:`IC0_LIMIT`)."""
    m = np.asarray(M.diagonal())[free]
    k = np.asarray(K.diagonal())[free]
    ok = m > 0
    return float(b * np.median(k[ok] / m[ok])) if ok.any() else float("inf")


@dataclass
class ConstrainedOperator:
    """``A = a M + b K`` restricted to the free rows: the kept factor of ``A_ff`` (or its
    diagonal, or the session whose kept preconditioner solves it) and the coupling ``A_fb``."""

    A_ff: sp.csr_matrix
    A_fb: sp.csr_matrix
    factor: object = None
    diagonal: np.ndarray | None = None
    session: object = None
    key: object = None
    keep_preconditioner: bool = True
    history: list = field(default_factory=list)
    perm: np.ndarray | None = None
    A_solve: sp.csr_matrix | None = None

    def reorder(self) -> None:
        """Solve in reverse Cuthill-McKee order (an ``ic0`` preconditioner asking for ``rcm``):
        ``A_ff`` permuted once here, so each solve permutes its right-hand side and solution
        once instead of the preconditioner permuting at every iteration; the matrix-vector
        products gain the band's locality too."""
        from scipy.sparse.csgraph import reverse_cuthill_mckee

        self.perm = reverse_cuthill_mckee(self.A_ff, symmetric_mode=True)
        self.A_solve = self.A_ff[self.perm][:, self.perm].tocsr()

    def initial_guess(self) -> np.ndarray | None:
        """The warm start: the quadratic through the last three solutions extrapolated one step,
        ``3 (x_n - x_{n-1}) + x_{n-2}`` (error ``O(dt^3)`` on a smooth solution: 7.8 IC(0)-PCG
        iterations per heat step at 250k unknowns against 16 from the line ``2 x_n - x_{n-1}``,
        ``benchmarks/bench_heat.py``); the line after two solves, the last one after one, none
        before."""
        h = self.history
        if len(h) == 3:
            return 3.0 * (h[2] - h[1]) + h[0]
        if len(h) >= 2:
            return 2.0 * h[-1] - h[-2]
        return h[-1] if h else None

    def solve_free(self, rhs: np.ndarray) -> np.ndarray:
        """``A_ff^-1 rhs``: a division, the kept factor's substitutions, or a warm-started
        iterative solve with the kept preconditioner (rebuilt every solve when
        ``keep_preconditioner`` is false: the comparison path); a failed one raises
        :class:`~femkit.errors.SolverError`."""
        if self.diagonal is not None:
            return rhs / self.diagonal
        if self.factor is not None:
            return self.factor.solve(rhs)
        x0 = self.initial_guess()   # kept in the solve's order
        perm = self.perm
        A = self.A_ff if perm is None else self.A_solve
        if perm is not None:
            rhs = rhs[perm]
        if self.keep_preconditioner:   # already in RCM order: the preconditioner's own is off
            x = self.session.solve_kept(A, rhs, x0, key=self.key, preconditioner_options=None
                                        if perm is None else {"ordering": "natural"})
        else:
            x = self.session.solve(A, rhs, x0)
        self.history = (self.history + [x])[-3:]
        if perm is None:
            return x
        out = np.empty_like(x)
        out[perm] = x
        return out


@dataclass
class LinearSystem:
    """``M``, ``K`` (``n x n`` CSR), the Dirichlet nodes and the time-dependent data.

    Parameters
    ----------
    M : sparse (n, n)
        Mass matrix (consistent, or diagonal when ``lumped``), ``rho_c`` / ``rho`` included.
    K : sparse (n, n)
        Stiffness matrix (``kappa`` included).
    fixed : (k,) int
        Dirichlet nodes (sorted, unique).
    load : callable ``t -> (n,)`` or None
        ``F(t)``: source and Neumann fluxes assembled at ``t`` (None: zero).
    boundary : callable ``t -> (k,)`` or None
        Values at ``fixed`` at ``t`` (None: zero).
    load_constant, boundary_constant : bool
        The data do not depend on ``t`` (evaluated once).
    lumped : bool
        ``M`` is diagonal.
    solver : SolverSpec
        Linear solver of the implicit steps (``direct``: one kept factor per matrix).
    keep_preconditioner : bool
        Iterative solvers keep one preconditioner per matrix (default); false rebuilds it
        every solve (the comparison path of the tests and the benchmark).
    """

    M: sp.csr_matrix
    K: sp.csr_matrix
    fixed: np.ndarray
    load: Callable[[float], np.ndarray] | None = None
    boundary: Callable[[float], np.ndarray] | None = None
    load_constant: bool = True
    boundary_constant: bool = True
    lumped: bool = False
    solver: SolverSpec = field(default_factory=lambda: SolverSpec("direct"))
    keep_preconditioner: bool = True
    stats: dict = field(default_factory=dict)
    _ops: dict = field(default_factory=dict, repr=False)
    _cache: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        self.M = sp.csr_matrix(self.M)
        self.K = sp.csr_matrix(self.K)
        n = self.K.shape[0]
        if self.M.shape != (n, n):
            raise InputError(f"M is {self.M.shape}, K is {self.K.shape}: they must match")
        self.fixed = np.unique(np.asarray(self.fixed, dtype=np.int64))
        mask = np.ones(n, dtype=bool)
        mask[self.fixed] = False
        self.free = np.flatnonzero(mask)
        self.n = n
        self.K_f = self.K[self.free]   # free rows, all columns: one SpMV per product
        self.M_f = self.M[self.free]
        self.stats.setdefault("factorizations", 0)
        self.stats.setdefault("solves", 0)
        self.stats.setdefault("factor_seconds", 0.0)
        self.session = self.solver.session(stats=self.stats)

    # ------------------------------------------------------------------ data
    def F(self, t: float) -> np.ndarray:
        """``F(t)`` on all nodes (zeros when there is no load)."""
        if self.load is None:
            return np.zeros(self.n)
        if self.load_constant:
            if "F" not in self._cache:
                self._cache["F"] = np.asarray(self.load(0.0), dtype=np.float64)
            return self._cache["F"]
        return np.asarray(self.load(t), dtype=np.float64)

    def g(self, t: float) -> np.ndarray:
        """Dirichlet values at ``fixed`` at time ``t``."""
        if self.boundary is None or self.fixed.size == 0:
            return np.zeros(self.fixed.size)
        if self.boundary_constant:
            if "g" not in self._cache:
                self._cache["g"] = np.asarray(self.boundary(0.0), dtype=np.float64)
            return self._cache["g"]
        return np.asarray(self.boundary(t), dtype=np.float64)

    @property
    def has_load(self) -> bool:
        return self.load is not None

    # ------------------------------------------------------------------ operators
    def operator(self, a: float, b: float) -> ConstrainedOperator:
        """The kept :class:`ConstrainedOperator` of ``A = a M + b K`` (built on first use)."""
        key = (float(a), float(b))
        op = self._ops.get(key)
        if op is not None:
            return op
        A = (a * self.M + b * self.K).tocsr() if b != 0.0 else (a * self.M).tocsr()
        A_f = A[self.free]
        A_ff = A_f[:, self.free].tocsr()
        A_fb = A_f[:, self.fixed].tocsr()
        op = ConstrainedOperator(A_ff, A_fb)
        if b == 0.0 and self.lumped:
            op.diagonal = A_ff.diagonal()
        elif self.solver.method in KEPT_FACTOR_METHODS and self.solver.backend == "femkit":
            t0 = time.perf_counter()
            op.factor = self.session.factorize(A_ff)
            self.stats["factor_seconds"] += time.perf_counter() - t0
        else:
            op.session, op.key = self.session, key
            op.keep_preconditioner = self.keep_preconditioner
            if (self.keep_preconditioner and self.solver.preconditioner == "ic0"
                    and self.solver.preconditioner_options.get("ordering") == "rcm"):
                op.reorder()
        self._ops[key] = op
        return op

    def rows(self, a: float, b: float) -> sp.csr_matrix:
        """``(a M + b K)[free]`` (free rows, all columns), kept: one SpMV per step."""
        key = ("rows", float(a), float(b))
        if key not in self._cache:
            self._cache[key] = (a * self.M_f + b * self.K_f).tocsr() if b != 0.0 else \
                (a * self.M_f).tocsr() if a != 1.0 else self.M_f
        return self._cache[key]

    def solve(self, a: float, b: float, rhs_free: np.ndarray, t: float, *,
              values: np.ndarray | None = None) -> np.ndarray:
        """The full vector ``x`` with ``x[fixed] = g(t)`` (or ``values``) and
        ``(a M + b K) x = r`` on the free rows, ``rhs_free`` being ``r`` there."""
        op = self.operator(a, b)
        g = self.g(t) if values is None else values
        x = np.empty(self.n)
        x[self.fixed] = g
        rhs = rhs_free - op.A_fb @ g if g.size and g.any() else rhs_free
        x[self.free] = op.solve_free(rhs)
        self.stats["solves"] += 1
        return x

    def energy(self, u: np.ndarray, v: np.ndarray | None = None) -> dict:
        """``1/2 u^T K u`` (``potential``), ``1/2 v^T M v`` (``kinetic``, with ``v``) and their
        ``total``; for the heat equation ``1/2 u^T M u`` is its ``thermal`` energy."""
        stiff, mass = self.quadratic_forms(u, v)
        out = {"potential": 0.5 * stiff}
        if v is None:
            out["thermal"] = 0.5 * mass
            return out
        out["kinetic"] = 0.5 * mass
        out["total"] = out["potential"] + out["kinetic"]
        return out

    def quadratic_forms(self, u: np.ndarray, v: np.ndarray | None = None) -> tuple[float, float]:
        """``(u^T K u, w^T M w)`` with ``w = v``, or ``u`` without ``v``."""
        w = u if v is None else v
        return float(u @ (self.K @ u)), float(w @ (self.M @ w))
