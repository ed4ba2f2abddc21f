"""Importing the solver layer, or solving directly / with CG, loads neither pyamg nor numba."""

from __future__ import annotations

import subprocess
import sys

CODE = """
import sys
import numpy as np, scipy.sparse as sp
import femkit.solvers as s
A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(30, 30), format="csr")
assert s.solve(A, np.ones(30), method="direct").converged
assert s.solve(A, np.ones(30), method="cg").converged
assert s.solve(A, np.ones(30), method="pcg", preconditioner="jacobi").converged
print(sorted(m for m in ("pyamg", "numba", "matplotlib", "gmsh") if m in sys.modules))
"""


def test_direct_and_cg_import_nothing_heavy():
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"
