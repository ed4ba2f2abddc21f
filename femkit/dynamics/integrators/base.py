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

Linear solves of the implicit methods go through the run's linear-solve session,
``ctx.session`` (:class:`femkit.solvers.session.LinearSession`, made from
``ctx.linear_solver``, the one solver description of femkit): it restricts nothing itself
(integrators pass ``A[free][:, free]``, :func:`femkit.solvers.operators.restrict`, or a
matrix-free :func:`femkit.solvers.operators.free_operator`) and owns every reuse between the
solves of a run -- SuperLU orderings, Cholesky symbolic analyses on a fixed pattern, factors
kept as preconditioners -- and the counters and time split it reports in ``ctx.stats``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import EquilibriumError, InputError, StabilityWarning
from ...solvers.session import LinearSession
from ...solvers.session import check_matrix_free as _check_matrix_free
from ...solvers.spec import SolverSpec

__all__ = [
    "StepContext",
    "StepperState",
    "Integrator",
    "box_length",
    "check_iteration_options",
    "check_matrix_free",
    "check_matrix_free_options",
    "NonlinearConvergenceWarning",
    "NewtonStepError",
    "note_unconverged",
    "check_contact",
    "contact_integrators",
    "contact_refusal",
]


@dataclass
class StepContext:
    """Linear-solver choice and per-run caches handed to every ``step``.

    Parameters
    ----------
    linear_solver : SolverSpec
        The linear solver of the implicit steps: method (``"direct"``, ``"cg"``, ``"pcg"``,
        ``"jacobi"``), preconditioner, stopping rule ``rtol``/``atol``/``maxiter`` and extra
        options (default: ``direct`` with ``rtol`` 1e-10).
    cache : dict
        Per-run caches (e.g. the fast mass-spring factorisation); filled by integrators.
    stats : dict
        Counters integrators report (``factorizations``, ``linear_solves``,
        ``newton_iterations`` list, ``linear_iterations``).
    """

    linear_solver: SolverSpec = field(default_factory=lambda: SolverSpec("direct"))
    cache: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)
    _session: LinearSession | None = field(default=None, init=False, repr=False, compare=False)

    @property
    def session(self) -> LinearSession:
        """The run's linear-solve session (made on first use from :attr:`linear_solver`, anew
        when that spec is replaced); its counters go to :attr:`stats`."""
        if self._session is None or self._session.spec is not self.linear_solver \
                or self._session.stats is not self.stats:
            self._session = LinearSession(self.linear_solver, self.stats)
        return self._session

    def count(self, key: str, n: int = 1) -> None:
        """Add ``n`` to counter ``key`` of :attr:`stats`."""
        self.stats[key] = self.stats.get(key, 0) + n

    def record(self, key: str, value) -> None:
        """Append ``value`` to the per-step list ``stats[key]`` (e.g. ``newton_iterations``)."""
        self.stats.setdefault(key, []).append(value)


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

    What the application layer derives from an integrator it reads here, not from a table of
    names: ``solves_per_step`` (an implicit step's cost in linear solves, the study prices'
    :func:`femkit.study.prices.implicit_run_seconds`) and ``work_precision`` (the method
    families of the work-precision study that run it: family -> ``(label, the option its sweep
    varies or None, options every run of the family takes)``,
    :func:`femkit.dynamics.work_precision.method_families`).
    """

    name = "integrator"
    order = 1
    implicit = False
    symplectic = False
    stability_bound = math.inf
    #: Linear solves an implicit step typically makes on the study scenes (Newton's implicit
    #: Euler: ~4 iterations measured on the springs_vs_elements scenes; the default for an
    #: integrator that declares none).
    solves_per_step = 4.0
    #: The work-precision method families that run this integrator (none by default).
    work_precision = {}
    #: The elements of an elastic body it integrates (names of :data:`femkit.elements.ELEMENTS`),
    #: or None: any (an integrator that sees only the system's forces and masses).
    elements = None

    #: Whether every step minimises with line-search steps bounded by the forces'
    #: ``step_bound`` (continuous collision detection), the condition under which barrier
    #: contact never lets surfaces pass through each other (Li et al. 2020). An integrator
    #: without it refuses a system with a force that ``requires_bounded_steps``.
    keeps_contact = False

    def start(self, system, x, v, t: float, dt: float, ctx: StepContext) -> StepperState:
        """Initial state: copies of ``x``, ``v`` with pinned velocities zeroed."""
        x = np.array(x, dtype=float, copy=True)
        v = np.array(v, dtype=float, copy=True)
        if x.shape != (system.n, system.dim) or v.shape != x.shape:
            raise InputError(
                f"{self.name}: x and v must have shape {(system.n, system.dim)}, "
                f"got {x.shape} and {v.shape}"
            )
        v[system.pinned_dofs] = 0.0
        check_contact(self, system)
        if getattr(self, "matrix_free", False):  # refuse a solver that needs the matrix up front
            check_matrix_free(self.name, ctx)
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


def contact_integrators() -> list[str]:
    """The registered integrators that keep barrier contact (``keeps_contact``)."""
    from .registry import INTEGRATORS

    return [n for n in INTEGRATORS.names() if getattr(INTEGRATORS.get(n), "keeps_contact", False)]


def contact_refusal(name: str) -> str:
    """The one-line refusal of barrier contact under integrator ``name``."""
    return (f"contact: integrator '{name}' cannot keep barrier contact intersection-free (its "
            "steps are not minimisations bounded by continuous collision detection); use "
            f"{' or '.join(contact_integrators())}")


def check_contact(integrator, system) -> None:
    """Refuse (one-line :class:`~femkit.errors.InputError`) a force that requires
    CCD-bounded steps under an integrator that does not keep contact."""
    needs = [f for f in system.forces if getattr(f, "requires_bounded_steps", False)]
    if needs and not integrator.keeps_contact:
        raise InputError(contact_refusal(integrator.name))


# ----------------------------------------------------------------------------- iterative steps
class NonlinearConvergenceWarning(StabilityWarning):
    """An iterative implicit step (``newton``, ``newmark``, ``variational_symplectic``) stopped
    at ``max_iterations`` without meeting its tolerance, so the step is not the method's exact
    step. A :class:`~femkit.errors.StabilityWarning` subclass, so scene runs record it in
    ``result.json``'s ``warnings``."""


class NewtonStepError(EquilibriumError):
    """The Newton iteration of an implicit step failed: its line search found no decrease above
    the round-off level of the step's objective, and a full Newton step did not lower the
    residual either (or the objective is not finite along the whole search).

    ``time`` is the time the step was to reach, ``residuals`` the norms of the gradient on the
    free dofs at every iterate of the failing step (the residual history), ``x`` the state the
    step started from. :func:`femkit.dynamics.simulate.simulate` attaches the trajectory up to
    that state as ``partial``.
    """

    def __init__(self, message: str, time: float, residuals, x=None):
        self.time = float(time)
        self.residuals = [float(r) for r in residuals]
        super().__init__(message, x=x)


def note_unconverged(name: str, ctx: StepContext, t: float, max_iterations: int, detail: str) -> None:
    """Count an unconverged step in ``ctx.stats["unconverged_steps"]`` and warn
    (:class:`NonlinearConvergenceWarning`) at the first one of the run (later ones are counted)."""
    ctx.count("unconverged_steps")
    if ctx.stats["unconverged_steps"] == 1:
        import warnings

        warnings.warn(NonlinearConvergenceWarning(
            f"{name}: the step ending at t = {t:.6g} stopped at max_iterations = {max_iterations} "
            f"without meeting its tolerance ({detail}); later unconverged steps are counted in "
            "stats['unconverged_steps']. Raise max_iterations or reduce dt"), stacklevel=3)


def box_length(x: np.ndarray) -> float:
    """Bounding-box diagonal of ``x`` (1 when it is 0): the length ``L`` of the stopping rules
    ``||dx||_inf <= tol * L`` of the iterative implicit steps.

    >>> box_length(np.array([[0.0, 0.0], [3.0, 4.0]]))
    5.0
    """
    return float(np.linalg.norm(np.ptp(x, axis=0))) or 1.0


def check_iteration_options(name: str, max_iterations: int, tol: float | None, *,
                            option: str = "max_iterations") -> None:
    """Raise :class:`~femkit.errors.InputError` unless ``max_iterations >= 1`` and ``tol > 0``
    (``tol=None``: no tolerance, sweeps only); ``option`` is the option's name in messages."""
    if int(max_iterations) < 1 or (tol is not None and not tol > 0):
        raise InputError(f"{name}: need {option} >= 1 and tol > 0, "
                         f"got {option}={max_iterations!r}, tol={tol!r}")


# ----------------------------------------------------------------------------- linear solves
def check_matrix_free(name: str, ctx: StepContext) -> None:
    """Refuse (:class:`~femkit.errors.InputError`) a linear solver that needs the assembled matrix
    for a matrix-free integrator (:func:`femkit.solvers.session.check_matrix_free`)."""
    _check_matrix_free(name, ctx.linear_solver)


def check_matrix_free_options(name: str, matrix_free: bool, reuse_factorization: bool) -> None:
    """Raise :class:`~femkit.errors.InputError` when both options are on (nothing to factorise)."""
    if matrix_free and reuse_factorization:
        raise InputError(f"{name}: matrix_free and reuse_factorization exclude each other "
                         "(there is no matrix to factorise)")
