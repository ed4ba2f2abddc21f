"""PETSc's ``KSPConvergedReason`` -> femkit's ``SolveResult.reason``.

The mapping decides only *why* the iteration stopped; ``converged`` is always decided by
the true residual ``||b - A x||`` recomputed (in parallel) at exit, as in the serial layer.
"""

from __future__ import annotations

#: KSPConvergedReason name -> femkit reason (PETSc manual, KSPConvergedReason)
REASON_MAP = {
    "CONVERGED_RTOL_NORMAL": "converged",
    "CONVERGED_ATOL_NORMAL": "converged",
    "CONVERGED_RTOL": "converged",
    "CONVERGED_ATOL": "converged",
    "CONVERGED_ITS": "direct",          # KSPPREONLY: one application of the factorisation
    "CONVERGED_HAPPY_BREAKDOWN": "converged",
    "CONVERGED_CG_NEG_CURVE": "breakdown",
    "CONVERGED_CG_CONSTRAINED": "breakdown",
    "CONVERGED_STEP_LENGTH": "converged",
    "DIVERGED_NULL": "breakdown",
    "DIVERGED_MAX_IT": "maxiter",
    "DIVERGED_DTOL": "stagnation",
    "DIVERGED_BREAKDOWN": "breakdown",
    "DIVERGED_BREAKDOWN_BICG": "breakdown",
    "DIVERGED_NONSYMMETRIC": "breakdown",
    "DIVERGED_INDEFINITE_PC": "breakdown",
    "DIVERGED_NANORINF": "non-finite",
    "DIVERGED_INDEFINITE_MAT": "breakdown",
    "DIVERGED_PCSETUP_FAILED": "breakdown",
}


def reason_name(PETSc, code: int) -> str:
    """The symbolic name of a ``KSPConvergedReason`` code (e.g. ``"DIVERGED_MAX_IT"``)."""
    for name, value in vars(PETSc.KSP.ConvergedReason).items():
        if name.isupper() and value == code and name != "ITERATING":
            return name
    return f"UNKNOWN_{code}"


def femkit_reason(name: str) -> str:
    """femkit reason for a KSPConvergedReason name (``breakdown`` for anything unlisted that
    is a divergence, ``converged`` for a convergence)."""
    if name in REASON_MAP:
        return REASON_MAP[name]
    return "converged" if name.startswith("CONVERGED") else "breakdown"
