"""The solver spec: a linear solver by name with its stopping rule, validated once.

The one description of "how to solve" in femkit: case files (``solver:``), scenes
(``linear_solver:``), studies (``solvers:``) and the implicit integrators all hold a
:class:`SolverSpec`; :meth:`SolverSpec.session` opens a
:class:`~femkit.solvers.session.LinearSession` for a sequence of solves (the one translator to
:func:`femkit.solvers.solve`). Defaults come from :mod:`femkit.solvers.core.defaults`, read when a
spec is made.

>>> import numpy as np, scipy.sparse as sp
>>> spec = SolverSpec.from_mapping({"method": "pcg", "preconditioner": "jacobi"})
>>> spec.label, spec.rtol
('pcg+jacobi', 1e-10)
>>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(20, 20), format="csr")
>>> spec.solve(A, np.ones(20)).converged
True
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Callable, Mapping

from ..errors import InputError, UnknownNameError, with_prefix
from .core import defaults

__all__ = ["SolverSpec"]


@dataclass(frozen=True)
class SolverSpec:
    """A linear solver by name with its stopping rule: what :func:`femkit.solvers.solve` takes.

    Attributes
    ----------
    method, preconditioner : names in ``femkit.solvers.SOLVERS`` / ``PRECONDITIONERS``
        (``preconditioner`` is ``"none"`` for every method but ``pcg``).
    rtol, atol, maxiter : the stopping rule ``||b - A x|| <= max(rtol ||b||, atol)``.
    options, preconditioner_options : keyword arguments of the method / preconditioner factory.
    label : how reports name this solver (default ``method`` or ``method+preconditioner``,
        with `` (petsc)`` appended on the PETSc backend).
    backend : ``femkit`` (these solvers) or ``petsc`` (the same names on PETSc KSP/PC,
        :mod:`femkit.solvers.petsc`; ``options`` then takes only ``omega``).
    petsc_options : PETSc options passed through (``{"pc_hypre_boomeramg_strong_threshold":
        0.5}``, as ``-pc_hypre_boomeramg_strong_threshold 0.5`` on PETSc's command line);
        ``backend: petsc`` only.
    """

    method: str
    preconditioner: str = "none"
    rtol: float = field(default_factory=lambda: defaults.DEFAULT_RTOL)
    atol: float = field(default_factory=lambda: defaults.DEFAULT_ATOL)
    maxiter: int | None = None
    options: dict = field(default_factory=dict)
    preconditioner_options: dict = field(default_factory=dict)
    label: str = ""
    backend: str = "femkit"
    petsc_options: dict = field(default_factory=dict)

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any] | None, where: str = "solver", *,
                     default_method: str = "pcg") -> "SolverSpec":
        """Check names against the registries and fill defaults from the one table.

        ``where`` (the key path in a file, e.g. ``linear_solver``) starts every message.

        Raises
        ------
        UnknownNameError
            Unknown method or preconditioner.
        InputError
            A preconditioner with a method other than ``pcg``; an unknown option name.
        """
        from .core.checks import check_options
        from .registry import BACKENDS, lookup

        def names(method, pc):
            try:
                return lookup(method, pc)
            except UnknownNameError as exc:
                key = "method" if exc.kind == "solver" else "preconditioner"
                raise with_prefix(exc, f"{where}.{key}") from None
            except InputError as exc:
                raise with_prefix(exc, f"{where}.preconditioner") from None

        def options_of(fn, opts, key, exclude=()):
            try:
                check_options(fn, opts, what=f"{where}.{key.split('_')[0]}", exclude=exclude)
            except InputError as exc:
                raise with_prefix(exc, f"{where}.{key}") from None

        d = dict(data or {})
        method = d.get("method") or default_method
        fn, pc, factory = names(method, d.get("preconditioner"))
        options = dict(d.get("options") or {})
        pc_options = dict(d.get("preconditioner_options") or {})
        backend = d.get("backend") or "femkit"
        petsc_options = dict(d.get("petsc_options") or {})
        try:
            BACKENDS.get(backend)
        except UnknownNameError as exc:
            raise with_prefix(exc, f"{where}.backend") from None
        if backend == "petsc":
            _check_petsc(method, pc, options, pc_options, petsc_options, where)
        else:
            if petsc_options:
                raise InputError(f"{where}.petsc_options: only used with backend: petsc")
            options_of(fn, options, "options", exclude=("rtol", "atol", "maxiter", "M", "callback"))
            if pc_options and pc == "none":
                raise InputError(f"{where}.preconditioner_options: no preconditioner is used")
            options_of(factory, pc_options, "preconditioner_options")
        label = d.get("label") or ((method if pc == "none" else f"{method}+{pc}")
                                   + (f" ({backend})" if backend != "femkit" else ""))
        return cls(method=method, preconditioner=pc,
                   rtol=float(d.get("rtol", defaults.DEFAULT_RTOL)),
                   atol=float(d.get("atol", defaults.DEFAULT_ATOL)),
                   maxiter=d.get("maxiter"), options=options,
                   preconditioner_options=pc_options, label=label, backend=backend,
                   petsc_options=petsc_options)

    @property
    def needs_hierarchy(self) -> bool:
        """Geometric multigrid (``method: fmg`` or ``preconditioner: gmg``): the caller passes a
        :class:`~femkit.mesh.MeshHierarchy` (``hierarchy=``, ``free=``) at solve time."""
        from .registry import PRECONDITIONERS, SOLVERS, traits

        return (traits(SOLVERS, self.method).needs_hierarchy
                or traits(PRECONDITIONERS, self.preconditioner).needs_hierarchy)

    def to_dict(self) -> dict:
        """The spec as a mapping (what ``result.json`` and the validated case data hold)."""
        return asdict(self)

    def replace(self, **changes) -> "SolverSpec":
        """A copy with some fields changed (labels follow method/preconditioner changes)."""
        d = self.to_dict()
        d.update(changes)
        if "label" not in changes:
            d["label"] = ""
        return SolverSpec.from_mapping(d)

    def session(self, stats: dict | None = None):
        """A :class:`~femkit.solvers.session.LinearSession` solving with this spec (factor,
        ordering and preconditioner reuse over a sequence of solves); counters go to ``stats``."""
        from .session import LinearSession

        return LinearSession(self, stats)

    def solve(self, A, b, x0=None, *, callback: Callable | None = None, **overrides):
        """Solve ``A x = b`` once with this spec (:meth:`LinearSession.run
        <femkit.solvers.session.LinearSession.run>`, the one translator to
        :func:`femkit.solvers.solve`).

        ``overrides`` (e.g. ``atol``) replace the spec's own stopping-rule values;
        ``options=`` / ``preconditioner_options=`` add run-time objects to the spec's own (the
        mesh hierarchy of geometric multigrid, see :attr:`needs_hierarchy`).
        """
        return self.session().run(A, b, x0, callback=callback, **overrides)


def _check_petsc(method: str, pc: str, options: dict, pc_options: dict, petsc_options: dict,
                 where: str) -> None:
    """Load-time checks of a ``backend: petsc`` spec (no petsc4py needed): names PETSc offers,
    ``options`` only ``omega`` (the jacobi iteration), no ``preconditioner_options``, and
    ``petsc_options`` keys and values PETSc's options database can hold."""
    from .petsc import names
    from .petsc.options import normalise
    from .registry import petsc_names

    try:
        names.resolve(method, pc, petsc_names())
    except UnknownNameError as exc:
        raise with_prefix(exc, f"{where}.{'method' if exc.kind.endswith('solver') else 'preconditioner'}") from None
    except InputError as exc:
        raise with_prefix(exc, f"{where}.preconditioner") from None
    bad = sorted(set(options) - ({"omega"} if method == "jacobi" else set()))
    if bad:
        raise InputError(f"{where}.options: {', '.join(bad)} not used by the petsc backend "
                         f"(PETSc settings go in petsc_options)")
    if pc_options:
        raise InputError(f"{where}.preconditioner_options: not used by the petsc backend "
                         f"(PETSc settings go in petsc_options)")
    try:
        normalise(petsc_options)
    except InputError as exc:
        raise with_prefix(exc, f"{where}.petsc_options") from None
