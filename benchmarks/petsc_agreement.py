"""PETSc backend vs serial femkit on the bundled Poisson cases, 1/2/3 ranks: the numbers behind
the tolerances of tests/petsc (by hand, with .venv-petsc from scripts/install-petsc.sh).

    PYTHONPATH=. python benchmarks/petsc_agreement.py

Per case and rank count: CG iterations (PETSc BoomerAMG vs femkit pyamg SA, rtol 1e-10;
high_contrast 1e-7), the largest entry-wise relative difference of the assembled matrices,
the largest solution difference relative to max |u|, and the relative difference of the L2
error against the exact solution.
"""

import json
import sys
import tempfile
from pathlib import Path

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "petsc"))

from conftest import run_batch  # noqa: E402
from problems import CASES  # noqa: E402
from test_mpi_poisson import RTOL, gathered_matrix, serial_reference  # noqa: E402


def main():
    cases = list(CASES)
    for ranks, mpirun in ((1, False), (2, True), (3, True)):
        out = run_batch(cases, ranks, Path(tempfile.mkdtemp()),
                        {c: [{"rtol": RTOL.get(c, 1e-10)}] for c in cases}, mpirun=mpirun)
        for c in cases:
            data = out[c]
            facts = json.loads(str(data["facts0"]))
            A, u_s, res_s, err_s = serial_reference(c, data, rtol=RTOL.get(c, 1e-10))
            A = sp.csr_matrix(A)
            D = (gathered_matrix(data) - A).tocoo()
            ref = np.maximum(np.abs(np.asarray(A[D.row, D.col]).ravel()), 1e-3 * abs(A).max())
            mat = float(np.max(np.abs(D.data) / ref)) if D.nnz else 0.0
            rel = np.max(np.abs(data["u0"] - u_s)) / np.max(np.abs(u_s))
            err = "" if err_s is None else \
                f"  L2 error rel diff {abs(facts['errors']['L2'] / err_s['L2'] - 1):.1e}"
            print(f"{ranks} rank(s) {c:16s} iterations petsc {facts['iterations']:3d} serial "
                  f"{res_s.iterations:3d}  matrix {mat:.1e}  u {rel:.1e}{err}")


if __name__ == "__main__":
    main()
