"""The femkit command line: exit codes, one-line errors, no partial output, results, lean runs."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from femkit.cli import main

ROOT = Path(__file__).parents[2]
CASES = ROOT / "cases"

SMALL = {
    "problem": "poisson",
    "mesh": {"geometry": "unit_square", "h": 0.2},
    "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
    "exact": {"u": "sin(pi*x)*sin(pi*y)",
              "grad": ["pi*cos(pi*x)*sin(pi*y)", "pi*sin(pi*x)*cos(pi*y)"]},
    "solver": {"method": "pcg", "preconditioner": "jacobi", "rtol": 1e-10},
    "output": {"dir": "out"},
}


def write(tmp_path, data, name="case.yaml"):
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    return p


def assert_bad_input(argv, pieces, capsys) -> str:
    """``femkit argv`` exits 2 with one line ``femkit: error: ...`` holding every piece; stderr."""
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("femkit: error: "), err
    for piece in pieces:
        assert piece in lines[0], (piece, lines[0])
    return err


def degenerate_vtu(path):
    """Two triangles of a unit square plus one zero-area triangle (three collinear nodes)."""
    import meshio

    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0, 0]], float)
    cells = [("triangle", np.array([[0, 4, 2], [4, 1, 2], [0, 2, 3], [0, 4, 1]]))]
    meshio.write(path, meshio.Mesh(pts, cells))
    return path


def bad_cases(tmp_path):
    def change(fn):
        d = json.loads(json.dumps(SMALL))
        fn(d)
        return d

    degenerate_vtu(tmp_path / "bad.vtu")
    return {
        "misspelled-key": (change(lambda d: d["solver"].update(preconditoner="amg")),
                           ["solver.preconditoner", "did you mean 'preconditioner'"]),
        "unknown-solver": (change(lambda d: d["solver"].update(method="bicgstab")),
                           ["solver.method", "bicgstab", "pcg"]),
        "unsafe-expression": (change(lambda d: d.update(source="__import__('os').system('x')")),
                              ["source", "__import__", "not allowed"]),
        "missing-mesh-file": (change(lambda d: d.update(mesh={"file": "nowhere/plate.msh"})),
                              [str((tmp_path / "nowhere" / "plate.msh").resolve())]),
        "degenerate-triangle": (change(lambda d: d.update(mesh={"file": "bad.vtu"})),
                                ["bad.vtu", "degenerate", "ids 3"]),
        "non-finite-source": (change(lambda d: d.update(source="log(x - 0.5)")),
                              ["source: expression 'log(x - 0.5)' gave non-finite values"]),
        "negative-kappa-expression": (change(lambda d: d.update(coefficient="x - 0.5")),
                                      ["coefficient", "> 0", "element(s) violate"]),
        "missing-tag": (change(lambda d: d["boundary"]["dirichlet"][0].update(tags=["lfet"])),
                        ["boundary.dirichlet[0].tags", "lfet", "left"]),
        # pure Neumann, f = 1 and zero flux: no solution exists (the data are at fault: exit 2)
        "incompatible-neumann": (change(lambda d: d.update(
            source=1, exact={"u": "0"},
            boundary={"neumann": [{"tags": ["boundary"], "flux": 0}], "nullspace": "mean_zero"})),
            ["pure-Neumann data are incompatible", "int f dx = 1", "int h ds = 0"]),
    }


@pytest.mark.parametrize("kind", ["misspelled-key", "unknown-solver", "unsafe-expression",
                                  "missing-mesh-file", "degenerate-triangle", "missing-tag",
                                  "non-finite-source", "negative-kappa-expression",
                                  "incompatible-neumann"])
def test_bad_input_exit_2_one_line_and_no_output(kind, tmp_path, capsys):
    data, pieces = bad_cases(tmp_path)[kind]
    case = write(tmp_path, data)
    before = set(tmp_path.iterdir())
    err = assert_bad_input(["solve", str(case)], pieces, capsys)
    assert "Traceback" not in err
    assert set(tmp_path.iterdir()) == before  # no output dir, no temp dir


def test_bad_input_via_subprocess_has_no_traceback(tmp_path):
    data, _ = bad_cases(tmp_path)["unsafe-expression"]
    proc = subprocess.run([sys.executable, "-m", "femkit.cli", "solve", str(write(tmp_path, data))],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert not (tmp_path / "out").exists()


def test_normal_run_writes_result_json_and_vtu(tmp_path, capsys):
    case = write(tmp_path, SMALL)
    assert main(["solve", str(case)]) == 0
    out = capsys.readouterr().out
    for word in ("points", "dofs", "pcg + jacobi", "iterations", "true residual", "L2", "assembly"):
        assert word in out
    res = json.loads((tmp_path / "out" / "result.json").read_text())
    for key in ("case", "problem", "mesh", "dofs", "nnz", "solver", "converged", "errors",
                "timings", "femkit_version", "files", "expressions"):
        assert key in res
    assert res["converged"] is True and res["solver"]["converged"] is True
    assert res["errors"]["L2"] < 0.1 and res["errors"]["H1_semi"] < 1.0
    assert set(res["timings"]) == {"mesh", "assembly", "boundary", "solve", "errors", "estimate", "output"}
    assert res["mesh"]["n_triangles"] > 0 and res["mesh"]["h_max"] > 0
    assert res["solver"]["residuals"][0] > res["solver"]["true_residual"]
    import meshio

    m = meshio.read(tmp_path / "out" / "solution.vtu")
    assert len(m.points) == res["mesh"]["n_points"]
    u = m.point_data["u"]
    exact = np.sin(np.pi * m.points[:, 0]) * np.sin(np.pi * m.points[:, 1])
    assert np.max(np.abs(u - exact)) == pytest.approx(res["errors"]["max_nodal"], rel=1e-12)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.yaml", "out"]


def test_rerun_replaces_older_output_and_quiet_prints_nothing(tmp_path, capsys):
    case = write(tmp_path, SMALL)
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "elsewhere" / "stale.txt").write_text("old run")
    (tmp_path / "elsewhere" / "result.json").write_text("{}")  # an older run (not user files)
    assert main(["solve", str(case), "--output", str(tmp_path / "elsewhere"), "--quiet"]) == 0
    assert capsys.readouterr().out == ""
    assert not (tmp_path / "elsewhere" / "stale.txt").exists()
    assert (tmp_path / "elsewhere" / "result.json").is_file()


def test_plot_and_xdmf_when_asked(tmp_path):
    data = dict(SMALL, output={"dir": "out", "plot": True, "xdmf": True})
    assert main(["solve", str(write(tmp_path, data)), "-q"]) == 0
    assert (tmp_path / "out" / "solution.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    from femkit.mesh import read_mesh

    assert read_mesh(tmp_path / "out" / "solution.xdmf").n_points > 0
    listed = json.loads((tmp_path / "out" / "result.json").read_text())["files"]
    assert sorted(listed) == sorted(p.name for p in (tmp_path / "out").iterdir())


def test_not_converged_exit_1_results_marked(tmp_path, capsys):
    data = dict(SMALL, solver={"method": "cg", "maxiter": 2, "rtol": 1e-12})
    code = main(["solve", str(write(tmp_path, data))])
    assert code == 1
    assert "did not converge" in capsys.readouterr().err
    res = json.loads((tmp_path / "out" / "result.json").read_text())
    assert res["converged"] is False and res["solver"]["reason"] == "maxiter"
    assert res["solver"]["iterations"] == 2


def test_check_unit_square_exits_0(capsys):
    code = main(["check", str(CASES / "poisson_unit_square.yaml")])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "stiffness K vs scikit-fem" in out and "pyamg" in out and "FAIL" not in out


def test_check_bad_input_exits_2(tmp_path, capsys):
    data, _ = bad_cases(tmp_path)["unknown-solver"]
    assert main(["check", str(write(tmp_path, data))]) == 2


LEAN = r"""
import sys
from femkit.cli import main
code = main(["solve", sys.argv[1], "--output", sys.argv[2], "--quiet"])
heavy = sorted(m for m in ("gmsh", "pyamg", "matplotlib", "skfem", "numba") if m in sys.modules)
print(code, ",".join(heavy))
"""


def test_lean_run_mesh_file_direct_imports_no_gmsh_pyamg_matplotlib(tmp_path):
    proc = subprocess.run([sys.executable, "-c", LEAN, str(CASES / "poisson_plate_mesh_file.yaml"),
                           str(tmp_path / "out")], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    code, heavy = proc.stdout.strip().split(" ") if " " in proc.stdout.strip() else (proc.stdout.strip(), "")
    assert code == "0"
    assert heavy == "", f"imported: {heavy}"
    assert (tmp_path / "out" / "result.json").is_file()


HELP = r"""
import sys, time
t = time.perf_counter()
import femkit.cli
femkit.cli.build_parser()
heavy = sorted(m for m in ("numpy", "scipy", "yaml", "jsonschema", "gmsh", "pyamg", "matplotlib")
               if m in sys.modules)
print(",".join(heavy))
"""


def test_help_imports_nothing_heavy():
    proc = subprocess.run([sys.executable, "-c", HELP], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == ""


@pytest.mark.parametrize("argv", [["--help"], ["solve", "--help"], ["check", "--help"]],
                         ids=["top", "solve", "check"])
def test_help_texts_describe_exit_codes_and_examples(argv, capsys):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert "exit codes" in out and f"femkit {'check' if argv[0] == 'check' else 'solve'} cases/" in out
    if argv[0] == "solve":
        assert "--output" in out and "result.json" in out
    if argv[0] == "check":
        assert "scikit-fem" in out and "pyamg" in out


def test_usage_error_exits_2_with_one_line(capsys):
    with pytest.raises(SystemExit) as info:
        main(["solv", "x.yaml"])
    assert info.value.code == 2
    assert capsys.readouterr().err.strip().count("\n") == 0


@pytest.mark.parametrize("path,pieces", [
    ("studies/stress.yaml", ["study file (kind: stability)", "femkit study ", "studies/stress.yaml`"]),
    ("studies/poisson_convergence.yaml", ["study file (kind: ", "run it with `femkit study "]),
    ("cases/stress/neumann.yaml", ["stress-suite case (type: poisson_neumann)",
                                   "`femkit study studies/stress.yaml`"]),
], ids=["stress-study", "convergence-study", "stress-case"])
def test_solve_on_a_study_or_stress_file_says_what_to_run(path, pieces, capsys):
    assert_bad_input(["solve", str(ROOT / path)], ["femkit: error: this is a ", *pieces], capsys)


def test_solve_pure_neumann_case_prints_how_the_constant_was_fixed(tmp_path, capsys):
    code = main(["solve", str(CASES / "poisson_neumann.yaml"), "--output", str(tmp_path / "o")])
    out = capsys.readouterr().out
    assert code == 0
    assert "pure Neumann: constant fixed by mean_zero" in out
    assert "relative imbalance" in out and "Dirichlet nodes" not in out
