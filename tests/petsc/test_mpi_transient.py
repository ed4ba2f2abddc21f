"""``femkit solve`` of heat and wave cases on PETSc under ``mpirun -n 2`` (and in one process
without mpirun) against the serial run.

Both runs use the PETSc environment's interpreter, so the mesh is the same gmsh output; every
frame of the distributed run (gathered on rank 0, written as frames/*.vtu) must equal the
serial frame to 1e-8 relative, one KSP kept across the steps (one factorisation for a fixed
``dt``), and the error history must be the serial one.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from conftest import ROOT
from test_cli_petsc import femkit, read_u


def _case(tmp_path, name: str, **changes) -> str:
    case = yaml.safe_load((ROOT / "cases" / f"{name}.yaml").read_text())
    case.update(changes)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(case))
    return path


def _frames_agree(serial, petsc, tol: float) -> int:
    names = sorted(p.name for p in (serial / "frames").iterdir())
    assert names == sorted(p.name for p in (petsc / "frames").iterdir())
    for name in names:
        p0, u0 = read_u(serial / "frames" / name)
        p1, u1 = read_u(petsc / "frames" / name)
        np.testing.assert_array_equal(p0, p1)
        assert np.max(np.abs(u1 - u0)) <= tol * max(np.max(np.abs(u0)), 1e-300), name
    return len(names)


@pytest.mark.usefixtures("needs_mpi")
@pytest.mark.parametrize("name,changes,kept,ranks", [
    ("heat_unit_square", {"mesh": {"geometry": "unit_square", "h": 0.06}, "t_end": 0.02}, 1, 2),
    ("heat_unit_square", {"mesh": {"geometry": "unit_square", "h": 0.06}, "t_end": 0.02,
                          "solver": {"method": "pcg", "preconditioner": "amg", "rtol": 1e-12}}, 1, 2),
    ("wave_unit_square", {"mesh": {"geometry": "unit_square", "h": 0.08}, "t_end": 0.1}, 2, 2),
    ("heat_unit_square", {"mesh": {"geometry": "unit_square", "h": 0.1}, "t_end": 0.02,
                          "integrator": "implicit_euler",
                          "solver": {"method": "pcg", "preconditioner": "jacobi", "rtol": 1e-12}}, 1, None),
], ids=["heat-cn-direct-2ranks", "heat-cn-pcg-amg-2ranks", "wave-newmark-2ranks",
        "heat-ie-pcg-jacobi-1rank-no-mpirun"])
def test_transient_on_petsc_equals_serial(name, changes, kept, ranks, tmp_path):
    path = _case(tmp_path, name, **changes)
    femkit(["solve", path, "--quiet", "--output", tmp_path / "serial"])
    femkit(["solve", path, "--quiet", "--backend", "petsc", "--output", tmp_path / "petsc"], ranks=ranks)
    serial = json.loads((tmp_path / "serial" / "result.json").read_text())
    petsc = json.loads((tmp_path / "petsc" / "result.json").read_text())
    lin = petsc["linear_solver"]
    assert (lin["backend"], lin["ranks"]) == ("petsc", ranks or 1)
    # one KSP per distinct step matrix, set up once and kept for every step
    assert lin["factorizations"] + lin["preconditioner_setups"] == kept
    assert lin["solves"] == serial["linear_solver"]["solves"] > 10
    assert _frames_agree(tmp_path / "serial", tmp_path / "petsc", 1e-8) == serial["frames"]
    for a, b in zip(serial["errors"]["history"], petsc["errors"]["history"]):
        assert b["L2"] == pytest.approx(a["L2"], rel=1e-6)
    for a, b in zip(serial["energies"], petsc["energies"]):   # summed over ranks
        for key in a:
            assert b[key] == pytest.approx(a[key], rel=1e-8, abs=1e-14)


@pytest.mark.usefixtures("needs_mpi")
def test_a_step_above_the_critical_one_is_refused_on_two_ranks_in_one_line(tmp_path):
    """Every rank finds it (replicated data): each exits 2 by itself, rank 0 says it once, no
    MPI_Abort, nothing written."""
    path = _case(tmp_path, "heat_explicit_lumped", dt=0.01)
    proc = femkit(["solve", path, "--backend", "petsc", "--output", tmp_path / "out"], ranks=2,
                  check=False)
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.startswith("femkit")]
    assert len(lines) == 1 and "exceeds the critical step" in lines[0], lines
    assert "MPI_ABORT" not in proc.stderr
    assert not (tmp_path / "out").exists()
