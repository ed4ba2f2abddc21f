"""femkit solver and preconditioner names -> PETSc KSP and PC types.

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

``sd`` (steepest descent) has no KSP counterpart and is not offered.
"""

from __future__ import annotations

from ...errors import UnknownNameError
from ..core.defaults import default_preconditioner
from ..core.pairing import check_pairing

#: method -> KSP type
KSP_TYPES = {"cg": "cg", "pcg": "cg", "jacobi": "richardson", "direct": "preonly"}

#: preconditioner -> (PC type, extra options set on the solve's prefix)
PC_TYPES = {
    "none": ("none", {}),
    "jacobi": ("jacobi", {}),
    "ic0": ("bjacobi", {"sub_pc_type": "icc", "sub_pc_factor_levels": 0, "sub_ksp_type": "preonly"}),
    "amg": ("hypre", {"pc_hypre_type": "boomeramg"}),
    "amg_rs": ("hypre", {"pc_hypre_type": "boomeramg"}),
    "amg_sa": ("gamg", {"pc_gamg_type": "agg"}),
}

#: what ``direct`` uses
DIRECT = ("cholesky", {"pc_factor_mat_solver_type": "mumps"})


def methods() -> list[str]:
    """Method names the PETSc backend understands."""
    return sorted(KSP_TYPES)


def preconditioners() -> list[str]:
    """Preconditioner names the PETSc backend understands."""
    return sorted(PC_TYPES)


def resolve(method: str, preconditioner: str | None) -> tuple[str, str, str, dict]:
    """``(ksp_type, pc_name, pc_type, extra_options)`` for femkit names.

    Raises
    ------
    UnknownNameError
        A name the PETSc backend does not offer (the valid ones are listed).
    InputError
        A preconditioner with a method other than ``pcg``.
    """
    if method not in KSP_TYPES:
        raise UnknownNameError("petsc solver", method, KSP_TYPES)
    if method == "direct":
        check_pairing(method, preconditioner)
        return "preonly", "mumps_cholesky", DIRECT[0], dict(DIRECT[1])
    if method == "jacobi":
        if preconditioner != "jacobi":  # the jacobi iteration is PCJACOBI under Richardson
            check_pairing(method, preconditioner)
        return "richardson", "jacobi", "jacobi", {}
    if preconditioner is None:
        preconditioner = default_preconditioner(method)
    if preconditioner not in PC_TYPES:
        raise UnknownNameError("petsc preconditioner", preconditioner, PC_TYPES)
    check_pairing(method, preconditioner)
    pc_type, extra = PC_TYPES[preconditioner]
    return "cg", preconditioner, pc_type, dict(extra)
