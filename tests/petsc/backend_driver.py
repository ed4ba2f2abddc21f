"""One process, no mpirun: PetscBackend on scipy matrices (what dynamics hands it); prints JSON.

Usage: .venv-petsc/bin/python tests/petsc/backend_driver.py OUT.npz
"""

import json
import sys

import numpy as np
import scipy.sparse as sp


def main(out):
    from femkit.solvers.registry import BACKENDS

    m = 30
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(m, m))
    A = (sp.kron(T, sp.identity(m)) + sp.kron(sp.identity(m), T)).tocsr()
    b = np.sin(np.arange(m * m))
    backend = BACKENDS.get("petsc")()
    specs = [("cg", None), ("pcg", "jacobi"), ("pcg", "ic0"), ("pcg", "amg"), ("pcg", "amg_sa"),
             ("direct", None), ("jacobi", None)]
    arrays, facts = {}, []
    for k, (method, pc) in enumerate(specs):
        seen = []
        r = backend.solve(A, b, method=method, preconditioner=pc, rtol=1e-10,
                          maxiter=20000 if method == "jacobi" else None,
                          callback=lambda x: seen.append(float(np.linalg.norm(x))))
        arrays[f"x{k}"] = r.x
        facts.append({"method": method, "pc": pc, "converged": r.converged, "reason": r.reason,
                      "iterations": r.iterations, "residuals": len(r.residuals),
                      "callbacks": len(seen), "ksp": r.info["ksp_type"], "pc_type": r.info["pc_type"],
                      "true_residual": r.true_residual, "tolerance": r.tolerance})
    errors = {}
    for key, call in {
        "asymmetric": lambda: backend.solve(A + sp.triu(A, 1) * 0.5, b, method="pcg"),
        "unknown_option": lambda: backend.solve(A, b, smoother="x"),
        "unknown_name": lambda: backend.solve(A, b, method="sd"),
    }.items():
        try:
            call()
            errors[key] = None
        except Exception as exc:  # noqa: BLE001
            errors[key] = f"{type(exc).__name__}: {exc}"
    dynamics = {}
    for name in ("implicit_euler", "newton", "newmark", "variational_symplectic"):
        for solver, pc in (("direct", "none"), ("pcg", "amg")):
            x, stats = cloth_run(name, solver, pc, "petsc")
            arrays[f"cloth_{name}_{solver}"] = x
            dynamics[f"{name}_{solver}"] = stats.get("linear_solves", 0)
    np.savez(out, A_data=A.data, A_indices=A.indices, A_indptr=A.indptr, b=b,
             facts=json.dumps({"solves": facts, "errors": errors, "dynamics": dynamics}), **arrays)


def cloth_system():
    """A 6 x 6 cloth under gravity, pinned at two corners."""
    from femkit.dynamics.forces import Gravity
    from femkit.dynamics.topology import cloth_grid

    return cloth_grid(6, 6, 1.0, 1.0, k_structural=500.0, k_shear=200.0, k_bending=50.0,
                      mass=0.01, plane="xy", forces=[Gravity(9.81)])


def cloth_run(integrator, solver, pc, backend="femkit", **integrator_options):
    """20 steps of the cloth; final positions and the context's counters."""
    from femkit.dynamics.integrators import StepContext
    from femkit.dynamics.simulate import simulate
    from femkit.solvers import SolverSpec

    spec = SolverSpec.from_mapping({"method": solver, "preconditioner": pc, "rtol": 1e-12,
                                    "backend": backend})
    ctx = StepContext(linear_solver=spec)
    traj = simulate(cloth_system(), integrator, 1e-2, 0.2, ctx=ctx, record_every=100,
                    **integrator_options)
    return traj.x[-1], ctx.stats


if __name__ == "__main__":
    main(sys.argv[1])
