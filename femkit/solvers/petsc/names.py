"""femkit solver and preconditioner names -> PETSc KSP and PC types.

The translation is not kept here: each method and preconditioner declares how PETSc spells
it (its ``petsc`` trait, in :mod:`femkit.solvers.registry`), and the registry hands the
table it derives (:class:`PetscNames`, from ``registry.petsc_names()``) to the PETSc backend.
This module only holds the table's shape and :func:`resolve`. What the registry declares:

============  =====================================================================
femkit name   PETSc
============  =====================================================================
``cg``        ``KSPCG``, ``PCNONE``
``pcg``       ``KSPCG`` with the preconditioner below (default ``amg``)
``jacobi``    ``KSPRICHARDSON`` (scale ``omega``) + ``PCJACOBI``: the weighted Jacobi iteration
``direct``    ``KSPPREONLY`` + ``PCCHOLESKY`` factored by MUMPS (``-pc_factor_mat_solver_type mumps``)
============  =====================================================================

Preconditioners (``pcg`` only): ``none`` -> ``PCNONE``; ``jacobi`` -> ``PCJACOBI``; ``ic0`` ->
``PCBJACOBI`` with ``PCICC`` (zero fill) on each rank's diagonal block: on one rank this is
IC(0) of the whole matrix, on N ranks it is *not* the serial IC(0) (the couplings between
ranks are dropped, so iterations grow with N); ``amg`` and ``amg_rs`` -> ``PCHYPRE``
BoomerAMG (classical Ruge-Stueben AMG, Henson & Yang 2002); ``amg_sa`` -> ``PCGAMG``
(smoothed aggregation, Adams et al.). Note that serial femkit's ``amg`` is smoothed
aggregation (pyamg), while here ``amg`` is BoomerAMG, the better-measured choice in PETSc
for this operator (6 CG iterations at 1e6 unknowns against 22 for GAMG).

Methods without a ``petsc`` trait (``sd``, ``fmg``, ``cholesky``; preconditioner ``gmg``)
are not offered.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ...errors import UnknownNameError
from ..core.defaults import default_preconditioner
from ..core.pairing import check_pairing


@dataclass(frozen=True)
class MethodSpelling:
    """How PETSc spells a femkit method: a KSP type, and the PC it fixes (``None``: the
    method takes the solve's preconditioner)."""

    ksp: str
    pc_name: str | None = None
    pc_type: str | None = None
    options: dict = field(default_factory=dict)


@dataclass(frozen=True)
class PetscNames:
    """The translation table the registry derives: method -> :class:`MethodSpelling`,
    preconditioner -> ``(PC type, options)``, and the methods that need a symmetric matrix."""

    methods: dict
    preconditioners: dict
    symmetric: frozenset = frozenset()


def resolve(method: str, preconditioner: str | None,
            table: PetscNames) -> tuple[str, str, str, dict]:
    """``(ksp_type, pc_name, pc_type, extra_options)`` for femkit names.

    Raises
    ------
    UnknownNameError
        A name the PETSc backend does not offer (the valid ones are listed).
    InputError
        A preconditioner with a method that fixes its own (or is not ``pcg``).
    """
    if method not in table.methods:
        raise UnknownNameError("petsc solver", method, table.methods)
    spelling = table.methods[method]
    if spelling.pc_type is not None:  # direct (MUMPS Cholesky), jacobi (PCJACOBI under Richardson)
        if preconditioner != spelling.pc_name:
            check_pairing(method, preconditioner)
        return spelling.ksp, spelling.pc_name, spelling.pc_type, dict(spelling.options)
    if preconditioner is None:
        preconditioner = default_preconditioner(method)
    if preconditioner not in table.preconditioners:
        raise UnknownNameError("petsc preconditioner", preconditioner, table.preconditioners)
    check_pairing(method, preconditioner)
    pc_type, extra = table.preconditioners[preconditioner]
    return spelling.ksp, preconditioner, pc_type, dict(extra)
