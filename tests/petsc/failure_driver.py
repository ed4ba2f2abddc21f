"""MPI driver for the failure tests: one rank fails, the others must not hang.

Usage: mpirun -n 2 .venv-petsc/bin/python tests/petsc/failure_driver.py MODE OUT
MODE "abort": rank 1 raises RuntimeError while rank 0 waits in a PETSc collective (a norm);
MODE "collective": rank 1's step raises InputError inside ``collective()``, so every rank
raises the same input error and exits 2 without MPI_Abort (rank 0 prints the one line).
"""

import sys


def main(mode, out):
    from femkit.errors import InputError
    from femkit.solvers.petsc import require_petsc
    from femkit.solvers.petsc.failure import abort_on_error, collective

    PETSc = require_petsc()
    comm = PETSc.COMM_WORLD
    mpi = comm.tompi4py()
    rank = comm.getRank()

    def step():
        if rank == 1:
            raise (InputError if mode == "collective" else RuntimeError)(f"{mode} failure on purpose")
        return rank

    with abort_on_error(mpi):
        if mode == "collective":
            try:
                collective(mpi, step)
            except InputError as exc:  # on every rank: each exits 2, rank 0 says why (as the CLI)
                if rank == 0:
                    print(f"femkit: error: {exc}", file=sys.stderr)
                sys.exit(2)
        else:
            v = PETSc.Vec().createMPI(10, comm=comm)
            if rank == 1:
                step()
            v.set(1.0)
            v.dot(v)  # rank 0 waits here for rank 1, which has failed (VecSet caches norms)
        with open(out, "w") as fh:  # never reached
            fh.write("finished")


if __name__ == "__main__":
    main(*sys.argv[1:3])
