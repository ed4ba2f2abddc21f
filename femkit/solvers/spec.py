"""The solver spec: a linear solver by name with its stopping rule, validated once.

The one description of "how to solve" in femkit: case files (``solver:``), scenes
(``linear_solver:``), studies (``solvers:``) and the implicit integrators all hold a
:class:`SolverSpec`, and :meth:`SolverSpec.solve` is the one translator to
:func:`femkit.solvers.solve`. Defaults come from :mod:`femkit.solvers.defaults`.

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
    label : how reports name this solver (default ``method`` or ``method+preconditioner``).
    """

    method: str
    preconditioner: str = "none"
    rtol: float = 1e-10
    atol: float = 0.0
    maxiter: int | None = None
    options: dict = field(default_factory=dict)
    preconditioner_options: dict = field(default_factory=dict)
    label: str = ""

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
        from .checks import check_options
        from .defaults import DEFAULT_ATOL, DEFAULT_RTOL, default_preconditioner
        from .registry import PRECONDITIONERS, SOLVERS

        def lookup(registry, name, key):
            try:
                return registry.get(name)
            except UnknownNameError as exc:
                raise with_prefix(exc, f"{where}.{key}") from None

        def options_of(fn, opts, key, exclude=()):
            try:
                check_options(fn, opts, what=f"{where}.{key.split('_')[0]}", exclude=exclude)
            except InputError as exc:
                raise with_prefix(exc, f"{where}.{key}") from None

        d = dict(data or {})
        method = d.get("method") or default_method
        fn = lookup(SOLVERS, method, "method")
        pc = d.get("preconditioner")
        if pc is None:
            pc = default_preconditioner(method)
        factory = lookup(PRECONDITIONERS, pc, "preconditioner")
        if pc != "none" and method != "pcg":
            raise InputError(f"{where}.preconditioner: {pc!r} needs method 'pcg', not "
                                f"{method!r} (drop it or use method: pcg)")
        options = dict(d.get("options") or {})
        pc_options = dict(d.get("preconditioner_options") or {})
        options_of(fn, options, "options", exclude=("rtol", "atol", "maxiter", "M", "callback"))
        if pc_options and pc == "none":
            raise InputError(f"{where}.preconditioner_options: no preconditioner is used")
        options_of(factory, pc_options, "preconditioner_options")
        label = d.get("label") or (method if pc == "none" else f"{method}+{pc}")
        return cls(method=method, preconditioner=pc,
                   rtol=float(d.get("rtol", DEFAULT_RTOL)),
                   atol=float(d.get("atol", DEFAULT_ATOL)),
                   maxiter=d.get("maxiter"), options=options,
                   preconditioner_options=pc_options, label=label)

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

    def solve(self, A, b, x0=None, *, callback: Callable | None = None, **overrides):
        """Solve ``A x = b`` with this spec: the one translator to :func:`femkit.solvers.solve`.

        ``overrides`` (e.g. ``atol``) replace the spec's own stopping-rule values.
        """
        from ..solvers import solve

        kw = dict(rtol=self.rtol, atol=self.atol, maxiter=self.maxiter)
        kw.update(overrides)
        return solve(A, b, x0, method=self.method,
                     preconditioner=self.preconditioner if self.method == "pcg" else None,
                     callback=callback,
                     preconditioner_options=self.preconditioner_options or None,
                     **kw, **self.options)
