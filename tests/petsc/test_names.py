"""femkit names -> KSP/PC types and KSPConvergedReason -> reason (no PETSc needed)."""

from __future__ import annotations

import pytest

from femkit.errors import InputError, UnknownNameError
from femkit.solvers.petsc import names
from femkit.solvers.petsc.reasons import femkit_reason
from femkit.solvers.registry import petsc_names


@pytest.mark.parametrize("method,pc,expected", [
    ("cg", None, ("cg", "none", "none")),
    ("pcg", None, ("cg", "amg", "hypre")),
    ("pcg", "jacobi", ("cg", "jacobi", "jacobi")),
    ("pcg", "ic0", ("cg", "ic0", "bjacobi")),
    ("pcg", "amg", ("cg", "amg", "hypre")),
    ("pcg", "amg_rs", ("cg", "amg_rs", "hypre")),
    ("pcg", "amg_sa", ("cg", "amg_sa", "gamg")),
    ("direct", None, ("preonly", "mumps_cholesky", "cholesky")),
    ("jacobi", None, ("richardson", "jacobi", "jacobi")),
], ids=lambda v: str(v))
def test_names_map_onto_ksp_and_pc(method, pc, expected):
    ksp, pc_name, pc_type, extra = names.resolve(method, pc, petsc_names())
    assert (ksp, pc_name, pc_type) == expected
    if pc_type == "hypre":
        assert extra == {"pc_hypre_type": "boomeramg"}
    if pc_name == "ic0":  # block Jacobi with ICC(0) per rank, not the serial IC(0)
        assert extra["sub_pc_type"] == "icc" and extra["sub_pc_factor_levels"] == 0
    if method == "direct":
        assert extra == {"pc_factor_mat_solver_type": "mumps"}


@pytest.mark.parametrize("method,pc,error,words", [
    ("sd", None, UnknownNameError, "valid petsc solvers: cg, direct, jacobi, pcg"),
    ("pcg", "ilu", UnknownNameError, "valid petsc preconditioners: amg, amg_rs, amg_sa"),
    ("cg", "amg", InputError, "only valid with method 'pcg'"),
    ("direct", "jacobi", InputError, "only valid with method 'pcg'"),
], ids=["sd-not-offered", "unknown-pc", "pc-with-cg", "pc-with-direct"])
def test_bad_names(method, pc, error, words):
    with pytest.raises(error, match=words):
        names.resolve(method, pc, petsc_names())


def test_the_table_is_what_the_registry_entries_declare():
    """Every registered method with a ``petsc`` trait is offered, the others are not."""
    from femkit.solvers.registry import SOLVERS, traits

    table = petsc_names()
    assert sorted(table.methods) == ["cg", "direct", "jacobi", "pcg"]
    assert table.symmetric == {"cg", "pcg", "direct", "cholesky"}
    assert all(traits(SOLVERS, m).petsc is table.methods[m] for m in table.methods)


@pytest.mark.parametrize("petsc,femkit", [
    ("CONVERGED_ATOL", "converged"), ("CONVERGED_RTOL", "converged"), ("CONVERGED_ITS", "direct"),
    ("DIVERGED_MAX_IT", "maxiter"), ("DIVERGED_INDEFINITE_PC", "breakdown"),
    ("DIVERGED_INDEFINITE_MAT", "breakdown"), ("DIVERGED_NANORINF", "non-finite"),
    ("DIVERGED_BREAKDOWN", "breakdown"), ("DIVERGED_DTOL", "stagnation"),
    ("DIVERGED_PCSETUP_FAILED", "breakdown"),
])
def test_converged_reasons(petsc, femkit):
    assert femkit_reason(petsc) == femkit
