"""``femkit solve CASE --backend petsc`` under mpirun against the serial ``femkit solve``.

Both runs use the PETSc environment's interpreter (``.venv-petsc/bin/femkit``), so the mesh is
the same gmsh output; the outputs must have the same layout (files, result.json keys), the
solution must agree within the solver tolerance and the error norms must be equal.
"""

from __future__ import annotations

import json
import os
import subprocess

import numpy as np
import pytest
import yaml

from conftest import MPIRUN, ROOT, TIMEOUT, VENV_PYTHON

FEMKIT = VENV_PYTHON.parent / "femkit"


def femkit(args, *, ranks=None, check=True):
    cmd = [str(FEMKIT)] + [str(a) for a in args]
    if ranks is not None:
        cmd = [MPIRUN, "--allow-run-as-root", "--oversubscribe", "-n", str(ranks)] + cmd
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1"}
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT, env=env, cwd=ROOT)
    if check and proc.returncode != 0:
        raise AssertionError(f"{cmd} failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    return proc


def read_u(path):
    import meshio

    m = meshio.read(path)
    return m.points[:, :2], m.point_data["u"]


@pytest.mark.usefixtures("needs_mpi")
@pytest.mark.parametrize("case,ranks", [("poisson_unit_square", 2), ("poisson_neumann", 2),
                                        ("poisson_plate_mesh_file", 3), ("poisson_unit_square", 1)],
                         ids=["unit_square-2ranks", "pure_neumann-2ranks",
                              "mesh_file_direct_mumps-3ranks", "unit_square-1rank-no-mpirun"])
def test_solve_backend_petsc_matches_serial(case, ranks, tmp_path):
    path = ROOT / "cases" / f"{case}.yaml"
    femkit(["solve", path, "--quiet", "--output", tmp_path / "serial"])
    femkit(["solve", path, "--quiet", "--backend", "petsc", "--output", tmp_path / "petsc"],
           ranks=ranks if ranks > 1 else None)
    serial = json.loads((tmp_path / "serial" / "result.json").read_text())
    petsc = json.loads((tmp_path / "petsc" / "result.json").read_text())
    assert sorted(os.listdir(tmp_path / "serial")) == sorted(os.listdir(tmp_path / "petsc"))
    assert sorted(serial) == sorted(petsc) and sorted(serial["solver"]) == sorted(petsc["solver"])
    assert (serial["backend"], petsc["backend"]) == ("femkit", "petsc")
    assert petsc["parallel"]["ranks"] == ranks and serial["parallel"] is None
    assert petsc["converged"] and petsc["solver"]["iterations"] == len(petsc["solver"]["residuals"]) - 1
    assert (petsc["dofs"], petsc["nnz"], petsc["mesh"]) == (serial["dofs"], serial["nnz"], serial["mesh"])
    assert set(petsc["timings"]) >= set(serial["timings"]) - {"output"}
    assert petsc["n_dirichlet"] == serial["n_dirichlet"]
    # the error estimate (computed on rank 0 from the gathered solution) matches the serial one
    assert petsc["error_estimate"]["energy"] == pytest.approx(serial["error_estimate"]["energy"],
                                                              rel=1e-6)
    if serial["nullspace"] is not None:  # pure Neumann: the same constant fixing, the same data check
        for key in ("mode", "how"):
            assert petsc["nullspace"][key] == serial["nullspace"][key]
        assert petsc["nullspace"]["source_integral"] == pytest.approx(
            serial["nullspace"]["source_integral"], rel=1e-9, abs=1e-14)
    p0, u0 = read_u(tmp_path / "serial" / "solution.vtu")
    p1, u1 = read_u(tmp_path / "petsc" / "solution.vtu")
    np.testing.assert_array_equal(p0, p1)
    tol = 1e-8 if serial["solver"]["method"] != "direct" else 1e-10
    assert np.max(np.abs(u1 - u0)) <= tol * np.max(np.abs(u0))
    for key, value in (serial["errors"] or {}).items():
        if value is not None:
            assert petsc["errors"][key] == pytest.approx(value, rel=1e-6), key


@pytest.mark.usefixtures("needs_mpi")
def test_large_solution_is_written_as_pvtu(tmp_path):
    case = yaml.safe_load((ROOT / "cases" / "poisson_unit_square.yaml").read_text())
    case["output"] = {"vtu": True, "gather_limit": 0}
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(case))
    femkit(["solve", path, "--quiet", "--backend", "petsc", "--output", tmp_path / "out"], ranks=3)
    files = sorted(os.listdir(tmp_path / "out"))
    assert "solution.pvtu" in files and "solution.vtu" not in files
    assert [f for f in files if f.startswith("solution_p") and f.endswith(".vtu")] == \
        [f"solution_p{r}.vtu" for r in range(3)]
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["parallel"]["gathered"] is False and "solution.pvtu" in result["files"]


@pytest.mark.usefixtures("needs_mpi")
def test_option_petsc_rejects_is_one_line_exit_2(tmp_path):
    case = yaml.safe_load((ROOT / "cases" / "poisson_unit_square.yaml").read_text())
    case["solver"]["petsc_options"] = {"pc_type": "no_such_pc"}
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(case))
    proc = femkit(["solve", path, "--backend", "petsc", "--output", tmp_path / "out"], ranks=2,
                  check=False)
    assert proc.returncode == 2, proc.stderr
    # femkit says it in one line (from rank 0; every rank exits 2 by itself, no MPI_Abort);
    # the rest of stderr is mpirun's own note about non-zero exits (mpirun --quiet drops it)
    lines = [ln for ln in proc.stderr.splitlines() if ln.startswith("femkit")]
    assert len(lines) == 1 and "PETSc rejected" in lines[0] and "unknown type" in lines[0], lines
    assert "MPI_ABORT" not in proc.stderr
    assert not (tmp_path / "out").exists()


def test_backend_petsc_without_petsc4py_is_one_line_exit_2(tmp_path, capsys):
    """In an interpreter without petsc4py (the default test environment)."""
    import importlib.util

    if importlib.util.find_spec("petsc4py") is not None:
        pytest.skip("petsc4py is importable in this interpreter (the error cannot occur)")
    from femkit.cli import main

    code = main(["solve", str(ROOT / "cases" / "poisson_unit_square.yaml"), "--backend", "petsc",
                 "--output", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "scripts/install-petsc.sh" in err[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("solver,words", [
    ({"backend": "trilinos"}, "solver.backend: unknown solver backend 'trilinos'"),
    ({"backend": "petsc", "method": "sd"}, "solver.method: unknown petsc solver 'sd'"),
    ({"petsc_options": {"ksp_rtol": 1e-3}}, "solver.petsc_options: only used with backend: petsc"),
], ids=["unknown-backend", "sd-not-on-petsc", "petsc-options-without-petsc"])
def test_solver_spec_errors_at_load(solver, words, tmp_path, capsys):
    case = yaml.safe_load((ROOT / "cases" / "poisson_unit_square.yaml").read_text())
    case["solver"] = solver
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(case))
    from femkit.cli import main

    assert main(["solve", str(path), "--output", str(tmp_path / "out")]) == 2
    assert words in capsys.readouterr().err


@pytest.mark.usefixtures("needs_petsc_venv")
def test_adaptive_case_refuses_the_petsc_backend(tmp_path):
    proc = femkit(["solve", ROOT / "cases" / "poisson_lshape_adaptive.yaml", "--backend", "petsc",
                   "--output", tmp_path / "out"], check=False)
    assert proc.returncode == 2
    assert proc.stderr.strip() == ("femkit: error: adaptive: adaptive refinement runs on the femkit "
                                   "backend only; remove adaptive or use solver.backend: femkit")
    assert not (tmp_path / "out").exists()


@pytest.mark.usefixtures("needs_mpi")
@pytest.mark.parametrize("element,refine", [("P1", 1), ("P2", 0)])
def test_solve_backend_petsc_on_tetrahedra_matches_serial(element, refine, tmp_path):
    """The bundled cube case (its mesh refined once for P1, PCG + AMG to 1e-10) on 2 ranks: the
    partition, the assembly and the pieces take tetrahedra, P2's dofs (edges owned by a rank of
    their own); u (P2: on every node of the quadratic cells) equals the serial one to 1e-8."""
    case = yaml.safe_load((ROOT / "cases" / "cube.yaml").read_text())
    case["mesh"]["refine"] = refine
    case["element"] = element
    if element == "P2":
        del case["quadrature"]     # P2's load rule: the cheapest exact for its products
    case["solver"] = {"method": "pcg", "preconditioner": "amg", "rtol": 1e-10}
    case["output"] = {"vtu": True}
    path = tmp_path / "cube.yaml"
    path.write_text(yaml.safe_dump(case))
    femkit(["solve", path, "--quiet", "--output", tmp_path / "serial"])
    femkit(["solve", path, "--quiet", "--backend", "petsc", "--output", tmp_path / "petsc"],
           ranks=2)
    serial = json.loads((tmp_path / "serial" / "result.json").read_text())
    petsc = json.loads((tmp_path / "petsc" / "result.json").read_text())
    assert petsc["mesh"] == serial["mesh"] and serial["mesh"]["dim"] == 3
    assert serial["mesh"]["element"] == element
    assert petsc["parallel"]["ranks"] == 2 and petsc["converged"]
    assert (petsc["dofs"], petsc["nnz"]) == (serial["dofs"], serial["nnz"])
    import meshio

    s, p = (meshio.read(tmp_path / d / "solution.vtu") for d in ("serial", "petsc"))
    np.testing.assert_array_equal(s.points, p.points)
    u0, u1 = s.point_data["u"], p.point_data["u"]
    assert np.max(np.abs(u1 - u0)) <= 1e-8 * np.max(np.abs(u0))
    for key, value in serial["errors"].items():
        assert petsc["errors"][key] == pytest.approx(value, rel=1e-6), key
