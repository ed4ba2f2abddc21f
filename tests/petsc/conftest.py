"""Running the MPI driver: skipped (with the reason) when .venv-petsc or mpirun is missing."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
VENV_PYTHON = ROOT / ".venv-petsc" / "bin" / "python"
MPIRUN = shutil.which("mpirun")
#: seconds one driver run may take before the test fails (a hang is a failure, not a wait)
TIMEOUT = 120

sys.path.insert(0, str(HERE))


def skip_reason() -> str | None:
    if not VENV_PYTHON.exists():
        return "PETSc environment absent: run scripts/install-petsc.sh to create .venv-petsc"
    return None


def mpi_skip_reason() -> str | None:
    return skip_reason() or (None if MPIRUN else "mpirun not found (scripts/install-petsc.sh "
                                                 "installs Open MPI)")


def run_driver(case: str, ranks: int, tmp_path: Path, solvers=({},), *, mpirun=True,
               check=True, script=HERE / "driver.py"):
    """Run the driver on ``ranks`` ranks (``mpirun=False``: one plain process); return the
    CompletedProcess and the loaded .npz (or None)."""
    out = tmp_path / f"{case}-{ranks}.npz"
    payload = solvers if isinstance(solvers, dict) else list(solvers)
    cmd = [str(VENV_PYTHON), str(script), case, str(out), json.dumps(payload)]
    if mpirun:
        cmd = [MPIRUN, "--allow-run-as-root", "--oversubscribe", "-n", str(ranks)] + cmd
    env = {**os.environ, "OMPI_MCA_rmaps_base_oversubscribe": "1", "OPENBLAS_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1", "PYTHONPATH": str(ROOT)}
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT, env=env, cwd=ROOT)
    if check and proc.returncode != 0:
        raise AssertionError(f"driver failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    data = np.load(out, allow_pickle=False) if out.exists() else None
    return proc, data


@pytest.fixture
def needs_mpi():
    reason = mpi_skip_reason()
    if reason:
        pytest.skip(reason)


@pytest.fixture
def needs_petsc_venv():
    reason = skip_reason()
    if reason:
        pytest.skip(reason)


def run_batch(cases, ranks: int, tmp_path: Path, specs: dict, *, mpirun=True) -> dict:
    """One driver launch for several cases (``specs``: case -> list of solver specs); returns
    case -> loaded .npz."""
    proc, data = run_driver(",".join(cases), ranks, tmp_path, specs, mpirun=mpirun)
    if len(cases) == 1:
        return {cases[0]: data}
    out = tmp_path / f"{','.join(cases)}-{ranks}.npz"
    return {c: np.load(out.with_suffix(f".{c}.npz"), allow_pickle=False) for c in cases}
