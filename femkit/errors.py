"""Every exception femkit raises on purpose.

All derive from :class:`FemkitError`, so a caller can catch the whole family.
The command line maps :class:`InputError` (and its subclasses) to exit code 2
and prints the one-line message; anything else is a bug.

Hierarchy::

    FemkitError
    ├── InputError                 bad input from the user (exit code 2)
    │   ├── CaseFileError          case/scene/study file: schema, keys, types, paths
    │   ├── ExpressionError        unsafe or malformed expression in a case file
    │   ├── UnknownNameError       unknown solver / preconditioner / integrator / geometry name
    │   ├── MeshError              unreadable or invalid mesh
    │   │   └── DegenerateMeshError  zero/near-zero-area triangles (ids attached)
    │   ├── HierarchyError         geometric multigrid (gmg, fmg) asked for without a matching
    │   │                          nested mesh hierarchy (the message names amg_rs)
    │   ├── AdaptivityError        bad adaptive-refinement setting (theta, target, budgets)
    │   ├── BudgetExceededError    predicted memory / time / steps / output above a limit
    │   │                          (before the run; ``force`` overrides)
    │   ├── BackendUnavailableError  a solver backend (PETSc: petsc4py, mpi4py) cannot be
    │                              imported; the message names scripts/install-petsc.sh
    │   │   └── ViewUnavailableError  pictures (``femkit view``, ``result.plot()``) without
    │   │                          pyvista, or without a display and off-screen OpenGL
    │   └── MaterialError          bad material parameters (E <= 0, nu outside (-1, 1/2), density <= 0)
    ├── SolverError                a linear solver could not do what was asked
    │   ├── NotSPDError            input to CG-type method is not symmetric positive definite
    │   ├── SingularSystemError    singular system (e.g. pure Neumann, inconsistent rhs)
    │   │   └── PureNeumannError   pure-Neumann data violating int f + int h = 0, or
    │   │                          nullspace: error (also an InputError: exit code 2)
    │   └── EquilibriumError       quasi-static Newton failed (line search exhausted, iteration
    │                              limit); carries the convergence record so far
    ├── InstabilityError           a time integrator blew up (method, step, time, energy ratio, dt_crit)
    └── RankFailureError           another MPI rank of a distributed run failed (its rank and message)

Warnings (not errors; the run goes on)::

    UserWarning
    └── StabilityWarning           an explicit integrator is started with dt above its critical
                                   step bound / omega_max (both numbers in the message)
"""

from __future__ import annotations

from typing import Iterable


class FemkitError(Exception):
    """Base class of all femkit errors."""


class InputError(FemkitError):
    """Bad input from the user: the command line exits with code 2."""


class CaseFileError(InputError):
    """A case, scene or study file is invalid (unknown key, wrong type, missing file ...)."""


class ExpressionError(InputError):
    """An expression in a case file is malformed or uses something outside the whitelist."""


class UnknownNameError(InputError, KeyError):
    """A name looked up in a registry does not exist.

    The message names the kind of thing, the name asked for and the valid names.
    """

    def __init__(self, kind: str, name: str, valid: Iterable[str]):
        self.kind = kind
        self.name = name
        self.valid = sorted(valid)
        super().__init__(f"unknown {kind} {name!r}; valid {_plural(kind)}: {', '.join(self.valid)}")

    def __str__(self) -> str:  # KeyError would otherwise repr() the message
        return self.args[0]


def _plural(noun: str) -> str:
    """English plural of the last word of ``noun`` (``geometry`` -> ``geometries``,
    ``study kind`` -> ``study kinds``, ``mesh`` -> ``meshes``).

    >>> [_plural(w) for w in ("geometry", "solver", "mesh", "key", "study kind", "status")]
    ['geometries', 'solvers', 'meshes', 'keys', 'study kinds', 'statuses']
    """
    if noun.endswith("y") and noun[-2:-1] not in tuple("aeiou"):
        return noun[:-1] + "ies"
    if noun.endswith(("s", "x", "z", "ch", "sh")):
        return noun + "es"
    return noun + "s"


class MeshError(InputError):
    """A mesh cannot be read or fails validation."""


class DegenerateMeshError(MeshError):
    """Triangles with zero or near-zero area; ``element_ids`` lists them."""

    def __init__(self, message: str, element_ids=()):
        self.element_ids = list(element_ids)
        super().__init__(message)


class MaterialError(InputError):
    """Invalid material parameters (Young's modulus <= 0, Poisson ratio outside (-1, 1/2),
    Lame moduli that make the material unstable at rest, density <= 0); the message names the
    parameter and its value."""


class BackendUnavailableError(InputError):
    """A solver backend cannot be used here (e.g. ``backend="petsc"`` without petsc4py):
    the one-line message says what is missing and how to install it."""


class ViewUnavailableError(BackendUnavailableError):
    """A picture (``femkit view``, ``result.plot()``) cannot be drawn here: pyvista is missing
    (``pip install femkit[view]``), or there is neither a display nor off-screen OpenGL (EGL or
    OSMesa; ``scripts/install-view.sh``). The one-line message names what to install."""


class RankFailureError(FemkitError):
    """Another rank of a distributed (MPI) run failed; ``rank`` is the first failing rank and
    ``message`` its error. Raised on every rank, so none is left waiting in a collective call."""

    def __init__(self, rank: int, message: str):
        self.rank = rank
        self.message = message
        super().__init__(f"rank {rank} failed: {message}")


class HierarchyError(InputError):
    """Geometric multigrid (preconditioner ``gmg``, method ``fmg``) was asked for without a nested
    mesh hierarchy, or with one that does not match the system; the message names the algebraic
    alternative (``amg_rs``)."""


class AdaptivityError(InputError):
    """A bad setting of adaptive refinement: Dörfler ``theta`` outside (0, 1], a target
    estimate <= 0, a dof / time / level budget <= 0, an unknown estimator."""


class BudgetExceededError(InputError):
    """A run's predicted cost exceeds a limit (available memory, or a stated budget).

    Raised before the run starts (:func:`femkit.cost.check_budget`); the one-line message gives
    the predicted sizes and cost, the limit and what to change. Attributes: ``what``
    (``memory``, ``time``, ``steps`` or ``output``), ``predicted``, ``limit`` (bytes, seconds,
    steps, bytes) and ``plan`` (the :class:`femkit.cost.Plan`).
    """

    def __init__(self, message: str, what: str = "", predicted: float = 0.0, limit: float = 0.0,
                 plan=None):
        self.what = what
        self.predicted = predicted
        self.limit = limit
        self.plan = plan
        super().__init__(message)


class SolverError(FemkitError):
    """A linear solver was handed something it cannot solve."""


class NotSPDError(SolverError):
    """The matrix handed to a CG-type method is not symmetric positive definite."""


class SingularSystemError(SolverError):
    """The system is singular (e.g. pure Neumann with an inconsistent right-hand side)."""


class PureNeumannError(SingularSystemError, InputError):
    """A pure-Neumann problem that cannot be solved as given: incompatible data
    (``int f dx + int h ds != 0`` beyond the tolerance), or ``nullspace="error"``.

    Both a :class:`SingularSystemError` (what it is) and an :class:`InputError` (whose
    fault it is: the data), so ``femkit solve`` exits with code 2 and writes nothing.
    """


class EquilibriumError(SolverError):
    """A quasi-static Newton solve failed (line search exhausted or iteration limit reached).

    ``record`` is the convergence record so far (load steps done, iterations, residual
    history), ``load_step`` the failing load step and ``x`` the last accepted configuration.
    """

    def __init__(self, message: str, record=None, load_step: int = -1, x=None):
        self.record = record
        self.load_step = load_step
        self.x = x
        super().__init__(message)


class InstabilityError(FemkitError):
    """A time integration became unstable.

    Attributes carry the facts: ``method``, ``step``, ``time``, ``energy_ratio``,
    ``dt``, ``dt_crit`` (``None`` when unknown) and ``partial`` (the results up to
    the last good step, if the caller kept them).
    """

    def __init__(self, method: str, step: int, time: float, energy_ratio: float,
                 dt: float, dt_crit: float | None, reason: str = "", partial=None):
        self.method = method
        self.step = step
        self.time = time
        self.energy_ratio = energy_ratio
        self.dt = dt
        self.dt_crit = dt_crit
        self.reason = reason
        self.partial = partial
        crit = f"{dt_crit:.3e}" if dt_crit is not None else "unknown"
        super().__init__(
            f"{method} became unstable at step {step} (t = {time:.6g}): "
            f"{reason or 'energy grew'}; energy ratio {energy_ratio:.3e}, dt = {dt:.3e}, "
            f"critical step {crit}"
        )


class StabilityWarning(UserWarning):
    """An explicit method is run with ``dt`` above its critical step ``bound / omega_max``.

    Issued by :func:`femkit.dynamics.simulate.simulate` before the run (``warnings.warn``);
    the message names ``dt``, the critical step and ``omega_max``.
    """


def with_prefix(exc: InputError, where: str) -> InputError:
    """The same exception (type and attributes kept) with ``where: `` before its one-line message."""
    cls = type(exc)
    new = cls.__new__(cls)
    new.__dict__.update(exc.__dict__)
    new.args = (f"{where}: {' '.join(str(exc).split())}",)
    return new
