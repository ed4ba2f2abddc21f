"""Projective dynamics (Bouaziz, Martin, Liu, Kavan & Pauly 2014): implicit Euler of an elastic
solid by local/global iterations.

The generalisation of :mod:`.fast_mass_spring` (Liu et al. 2013) from springs to element strains.
Implicit Euler minimises ``g(x) = 1/(2 h^2) ||x - y||_M^2 + E(x) - f_ext . x`` with
``y = x_n + h v_n``. The as-rigid-as-possible energy of each element,
``vol mu |F - R|^2 = w/2 min_{R in SO(d)} |D_e x - R|^2`` (``w = 2 mu vol``, ``D_e x = F_e``),
and optionally a volume band ``w_v/2 min_{J_min <= det B <= J_max} |D_e x - B|^2``
(``w_v = volume_stiffness vol``) are written as distances to constraint sets, so alternating

* local step: project every ``F_e`` onto its set (compiled, :mod:`.projective_local`), and
* global step: ``(M + h^2 L) x = M y + h^2 (sum_e w_e D_e^T T_e + f_ext)``,
  ``L = sum_e w_e D_e^T D_e`` constant,

decreases ``g`` monotonically; its fixed point is the implicit Euler step of the ARAP energy,
i.e. of the co-rotational material with ``lam = 0`` (``mu sum (s_i - 1)^2``), whose Newton
solution it equals (``tests/dynamics/test_projective.py``). ``mu`` is each region's material's
shear modulus; the other constants of the body's materials are not used (projective dynamics has
its own energy). The coordinates decouple, so the ``n x n`` matrix ``M + h^2 L`` is factorised
once per run through the run's linear-solve session (``ctx.session.factorize``: CHOLMOD with the
``cholesky`` solver, else SuperLU) and serves all ``d`` coordinates; pinned nodes are eliminated
as in fast mass-spring (rollers per coordinate, :class:`~.component_pins.ComponentSolve`).

External forces: those flagged constant (gravity) once per step, the others (contact, damping)
per iteration at velocity ``(x - x_n) / h``, explicitly (not in the matrix).

Run record (``ctx.stats``): per step ``projective_iterations``, the final relative global
residual ``projective_residual`` = ``||A x_k - b(x_k)|| / ||b(x_k)||`` -- ``h^2`` times the
gradient of ``g`` at the last iterate over the right-hand side, the residual Newton would see --
and the local residual ``projective_local`` (the constraints' energy ``sum w/2 |F - T|^2``).
``iterations`` sweeps per step (Bouaziz et al.: 10), or fewer when ``tol`` is set and the
relative residual falls below it. Convergence is linear (the rate is measured in the tests);
order 1, unconditionally stable.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...solvers.operators import restrict
from .base import Integrator, StepContext, StepperState, check_iteration_options
from .component_pins import ComponentSolve
from .registry import register


@dataclass
class _Operators:
    factor: object             # ComponentSolve (rollers eliminated per coordinate)
    free: np.ndarray           # nodes free in some component
    pinned: np.ndarray         # nodes held in every component
    M: np.ndarray              # (n, 1) lumped masses
    A_fp: object               # free x pinned block of M + h^2 L
    w_rot: np.ndarray
    w_vol: np.ndarray
    force: object              # the elastic force (left out of the external forces)
    L: object                  # n x n, for the residual


def _elastic_force(system):
    from ..forces.elastic import ElasticForce

    found = [f for f in system.forces if isinstance(f, ElasticForce)]
    if len(found) != 1 or system.n_springs:
        raise InputError(f"projective dynamics needs a system with exactly one elastic solid and "
                         f"no springs (femkit.dynamics.system.elastic_system); got "
                         f"{len(found)} elastic force(s) and {system.n_springs} springs "
                         "(use fast_mass_spring for springs)")
    element = getattr(found[0].body, "element", "P1")
    if element not in Projective.elements:
        raise InputError(f"projective dynamics integrates {', '.join(Projective.elements)} "
                         f"bodies only (one deformation gradient per element), got {element}")
    return found[0]


def arap_laplacian(body, weights: np.ndarray):
    """``L = sum_e w_e D_e^T D_e`` (``n x n``, one coordinate): entry ``(i, j)`` sums
    ``w_e g_i . g_j`` over the elements holding both nodes."""
    import scipy.sparse as sp

    r = body.rest
    nv = r.cells.shape[1]
    vals = weights[:, None, None] * np.einsum("enb,emb->enm", r.gradients, r.gradients)
    rows = np.repeat(r.cells, nv, axis=1).ravel()
    cols = np.tile(r.cells, (1, nv)).ravel()
    return sp.csr_matrix((vals.ravel(), (rows, cols)), shape=(body.n, body.n))


@register("projective")
@dataclass(frozen=True)
class Projective(Integrator):
    """Projective dynamics (module docstring).

    Parameters
    ----------
    iterations : int
        Local/global sweeps per step (an upper bound when ``tol`` is set).
    tol : float, optional
        Stop when the relative global residual is at most ``tol``.
    volume_stiffness : float
        Weight per unit volume of the volume-band constraint (0: ARAP only).
    volume_min, volume_max : float
        The band ``J_min <= det F <= J_max`` (``0 < J_min <= 1 <= J_max``).
    """

    iterations: int = 10
    tol: float | None = None
    volume_stiffness: float = 0.0
    volume_min: float = 1.0
    volume_max: float = 1.0

    order = 1
    implicit = True
    symplectic = False
    #: one kept factorisation: ~2 step-equivalents for its cheap local/global sweeps
    solves_per_step = 2.0
    #: needs an elastic solid (no springs) and integrates its own ARAP energy, not the body's
    #: material: generic every-integrator tests leave it out
    solids_only = True
    #: its local step projects one deformation gradient per element: P1 only
    elements = ("P1",)

    def __post_init__(self):
        check_iteration_options(self.name, self.iterations, self.tol, option="iterations")
        if not (self.volume_stiffness >= 0.0 and 0.0 < self.volume_min <= 1.0 <= self.volume_max
                and np.isfinite(self.volume_max)):
            raise InputError(f"{self.name}: need volume_stiffness >= 0 and 0 < volume_min <= 1 <= "
                             f"volume_max < inf, got {self.volume_stiffness!r}, "
                             f"{self.volume_min!r}, {self.volume_max!r}")

    def _operators(self, system, dt: float, ctx: StepContext) -> _Operators:
        key = (float(dt), system, system.mass, system.pinned_dofs, system.forces)
        cached = ctx.cache.get("projective")
        if cached is not None and cached[0][0] == key[0] and all(
                a is b for a, b in zip(cached[0][1:], key[1:])):
            return cached[1]
        import scipy.sparse as sp

        force = _elastic_force(system)
        body = force.body
        mu = np.empty(body.rest.n_cells)
        for elems, mat in body.groups:
            mu[elems] = mat.mu
        vol = body.rest.volumes
        w_rot = 2.0 * mu * vol
        w_vol = float(self.volume_stiffness) * vol
        mass = np.asarray(system.mass, dtype=float)
        L = arap_laplacian(body, w_rot + w_vol)
        A = (sp.diags(mass) + (dt * dt) * L).tocsr()
        free = np.flatnonzero(~system.pinned)
        pinned = np.flatnonzero(system.pinned)
        ops = _Operators(ComponentSolve(restrict(A, free), system.pinned_dofs[free],
                                        ctx.session.factorize), free, pinned, mass[:, None],
                         A[free][:, pinned].tocsr(), w_rot, w_vol, force, L)
        ctx.cache["projective"] = (key, ops)
        return ops

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        from ...interrupt import active_flag
        from .projective_local import local_step

        stop = active_flag()  # a stop request ends the sweeps: the run then stops after this step
        h = dt
        ops = self._operators(system, h, ctx)
        free, pinned = ops.free, ops.pinned
        body = ops.force.body
        r = body.rest
        xn = state.x
        t_new = state.t + h
        x = xn + h * state.v
        x[pinned] = xn[pinned]
        held = xn[free]
        roller = ~system.pinned_dofs[free] if system.partially_pinned else None
        const = ops.M * x + (h * h) * system.constant_force()
        others = [f for f in system.forces if not f.constant and f is not ops.force]
        jmin, jmax = float(self.volume_min), float(self.volume_max)
        rel = np.inf
        local = 0.0
        k = 0
        while True:
            rhs = const.copy()
            target = np.zeros_like(x)
            local = local_step(x, r.cells, r.gradients, ops.w_rot, ops.w_vol, jmin, jmax, target)
            rhs += (h * h) * target
            if others:
                fx = np.zeros_like(x)
                v = (x - xn) / h
                for f in others:
                    f.add_force(x, v, t_new, fx)
                rhs += (h * h) * fx
            b = rhs[free]
            if pinned.size:
                b -= ops.A_fp @ xn[pinned]
            # residual of the current iterate: A x_k - b(x_k) (h^2 times the gradient of g)
            Ax = ops.M[free] * x[free] + (h * h) * (ops.L @ x)[free]
            res, rn = Ax - rhs[free], rhs[free]
            if roller is not None:      # a held component has no equation
                res, rn = res[roller], rn[roller]
            rel = float(np.linalg.norm(res) / max(np.linalg.norm(rn), 1e-300))
            if k >= int(self.iterations) or (self.tol is not None and rel <= self.tol) or stop:
                break
            x[free] = ops.factor.solve(np.asfortranarray(b), held)
            k += 1
        ctx.record("projective_iterations", k)
        ctx.record("projective_residual", rel)
        ctx.record("projective_local", float(local))
        return StepperState(x, (x - xn) / h, t_new)

