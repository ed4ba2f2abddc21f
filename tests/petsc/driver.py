"""MPI driver of tests/petsc: solve bundled cases with the PETSc backend, once per solver
spec, and save on rank 0 the mesh, then per solve the gathered solution, matrix and facts.

Usage: mpirun -n N .venv-petsc/bin/python tests/petsc/driver.py CASES OUT.npz SOLVERS_JSON
CASES: one name, or several separated by commas (one launch for all; case c is then saved to
OUT with ``.c.npz`` for ``.npz``). SOLVERS_JSON: a list of {"method", "preconditioner", "rtol",
"petsc_options", "pvtu"} (any may be left out; "pvtu": true also writes solution{k}.pvtu and
its pieces next to OUT), or {case: list} per case.
"""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from problems import CASES, make_mesh, mesh_arrays  # noqa: E402


def main(argv):
    names, out = argv[0].split(","), argv[1]
    specs = json.loads(argv[2]) if len(argv) > 2 else [{}]
    for name in names:
        target = out if len(names) == 1 else str(Path(out).with_suffix(f".{name}.npz"))
        solve_case(name, target, specs[name] if isinstance(specs, dict) else specs)


def solve_case(name, out, specs):
    from femkit.solvers.petsc import require_petsc
    from femkit.fem.distributed.assembly import gather_matrix
    from femkit.solvers.petsc.failure import abort_on_error
    from femkit.fem.distributed.poisson import broadcast_mesh, solve_poisson

    PETSc = require_petsc()
    comm = PETSc.COMM_WORLD
    arrays = {}
    with abort_on_error(comm.tompi4py()):
        mesh = broadcast_mesh(lambda: make_mesh(name), comm)
        problem, (exact, grad) = CASES[name][1](mesh)
        for k, spec in enumerate(specs):
            sol = solve_poisson(problem, method=spec.get("method", "pcg"),
                                preconditioner=spec.get("preconditioner"),
                                rtol=spec.get("rtol", 1e-10), maxiter=spec.get("maxiter", 5000),
                                petsc_options=spec.get("petsc_options"), exact=exact,
                                grad_exact=grad)
            A = gather_matrix(sol.system.A, sol.system.layout, comm)
            if spec.get("pvtu"):
                from femkit.fem.distributed.pvtu import write_pvtu

                write_pvtu(Path(out).parent, f"solution{k}", mesh, sol.u_vec, sol.system.layout,
                           comm)
            if comm.getRank() == 0:
                r = sol.result
                facts = {"converged": r.converged, "iterations": r.iterations, "reason": r.reason,
                         "relative_residual": r.relative_residual, "info": r.info,
                         "method": r.method, "preconditioner": r.preconditioner,
                         "errors": sol.errors, "timings": sol.timings, "partition": sol.partition,
                         "residuals": r.residuals.tolist()}
                arrays.update({f"u{k}": sol.u, f"A{k}_data": A.data, f"A{k}_indices": A.indices,
                               f"A{k}_indptr": A.indptr, f"facts{k}": json.dumps(facts)})
        if comm.getRank() == 0:
            np.savez(out, n_solves=len(specs), **arrays, **mesh_arrays(mesh))


if __name__ == "__main__":
    from femkit.errors import InputError

    try:
        main(sys.argv[1:])
    except InputError as exc:  # raised on every rank (as the CLI does: rank 0 says it, exit 2)
        import os

        if os.environ.get("OMPI_COMM_WORLD_RANK", "0") == "0":
            print(f"femkit: error: {exc}", file=sys.stderr)
        sys.exit(2)
