"""PetscBackend on a scipy matrix in one process (no mpirun), against femkit's own solvers."""

from __future__ import annotations

import json
import os
import subprocess

import numpy as np
import pytest
import scipy.sparse as sp

from conftest import HERE, ROOT, TIMEOUT, VENV_PYTHON, skip_reason

from femkit.solvers import solve



@pytest.fixture(scope="module")
def run(tmp_path_factory):
    reason = skip_reason()
    if reason:
        pytest.skip(reason)
    out = tmp_path_factory.mktemp("backend") / "backend.npz"
    subprocess.run([str(VENV_PYTHON), str(HERE / "backend_driver.py"), str(out)], check=True,
                   timeout=TIMEOUT, cwd=ROOT, capture_output=True,
                   env={**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"})
    return np.load(out)


@pytest.mark.usefixtures("needs_petsc_venv")
def test_every_name_solves_like_femkit(run):
    n = len(run["A_indptr"]) - 1
    A = sp.csr_matrix((run["A_data"], run["A_indices"], run["A_indptr"]), shape=(n, n))
    b = run["b"]
    ref = solve(A, b, method="direct").x
    facts = json.loads(str(run["facts"]))
    for k, f in enumerate(facts["solves"]):
        assert f["converged"], f
        x = run[f"x{k}"]
        assert np.linalg.norm(b - A @ x) <= 1e-10 * np.linalg.norm(b) * (1 + 1e-12)
        assert np.max(np.abs(x - ref)) <= 1e-6 * np.max(np.abs(ref)), f
        if f["method"] != "direct":
            # one residual per iteration after the initial one; callback once per iteration
            assert f["residuals"] == f["iterations"] + 1 and f["callbacks"] == f["iterations"]
    its = {(f["method"], f["pc"]): f["iterations"] for f in facts["solves"]}
    # on one rank block-Jacobi/ICC is IC(0) of the whole matrix: the same iterations as femkit's
    femkit_ic0 = solve(A, b, method="pcg", preconditioner="ic0", rtol=1e-10).iterations
    assert abs(its[("pcg", "ic0")] - femkit_ic0) <= 2, (its, femkit_ic0)
    femkit_cg = solve(A, b, method="cg", rtol=1e-10).iterations
    assert abs(its[("cg", None)] - femkit_cg) <= 2, (its, femkit_cg)


@pytest.mark.usefixtures("needs_petsc_venv")
def test_errors_are_femkit_errors(run):
    errors = json.loads(str(run["facts"]))["errors"]
    assert errors["asymmetric"].startswith("NotSPDError: pcg needs a symmetric positive definite")
    assert errors["unknown_option"].startswith("InputError: unknown option(s) 'smoother'")
    assert errors["unknown_name"].startswith("UnknownNameError: unknown petsc solver 'sd'")


@pytest.mark.usefixtures("needs_petsc_venv")
@pytest.mark.parametrize("integrator", ["implicit_euler", "newton", "newmark",
                                        "variational_symplectic"])
def test_implicit_dynamics_on_the_petsc_backend(run, integrator):
    """``linear_solver: {backend: petsc}``: the implicit integrators' linear solves go to PETSc
    (MUMPS Cholesky for direct, BoomerAMG-PCG for pcg) and the trajectory matches femkit's
    direct solver (a 6 x 6 cloth, 20 steps, rtol 1e-12)."""
    import sys

    sys.path.insert(0, str(HERE))
    from backend_driver import cloth_run

    x_ref, _ = cloth_run(integrator, "direct", "none")
    facts = json.loads(str(run["facts"]))["dynamics"]
    for solver in ("direct", "pcg"):
        assert facts[f"{integrator}_{solver}"] > 0  # the solves went through femkit.solvers.solve
        x = run[f"cloth_{integrator}_{solver}"]
        assert np.max(np.abs(x - x_ref)) <= 1e-8 * np.max(np.abs(x_ref)), solver


@pytest.mark.parametrize("integrator,options,words", [
    ("fast_mass_spring", {}, "factorisation kept for the whole run"),
    ("implicit_euler", {"reuse_factorization": True}, "reuse_factorization keeps femkit's SuperLU"),
    ("implicit_euler", {"matrix_free": True}, "matrix-free solves run in femkit's own solvers"),
], ids=["fast_mass_spring", "reuse_factorization", "matrix_free"])
def test_dynamics_paths_that_keep_femkit_refuse_petsc(integrator, options, words):
    """No silent fallback: these paths use femkit's own factor/products, so backend petsc is an
    input error (raised before any PETSc import, so this runs without PETSc too)."""
    import sys

    from femkit.errors import InputError

    sys.path.insert(0, str(HERE))
    from backend_driver import cloth_run

    with pytest.raises(InputError, match=words):
        cloth_run(integrator, "direct" if not options.get("matrix_free") else "cg", "none",
                  "petsc", **options)
