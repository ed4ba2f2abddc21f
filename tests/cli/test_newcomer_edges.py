"""A newcomer's rough edges: ``python -m femkit``, duplicate YAML keys, output file modes."""

import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared case
from _small import SMALL  # noqa: E402

from femkit.cli import main
from femkit.io.atomic import atomic_path, atomic_write_text


def test_python_m_femkit_runs_the_command_line():
    proc = subprocess.run([sys.executable, "-m", "femkit", "--help"], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "solve" in proc.stdout and "study" in proc.stdout


def test_python_m_femkit_passes_the_exit_code(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "femkit", "solve", str(tmp_path / "missing.yaml")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "not found" in proc.stderr


@pytest.mark.parametrize("text, key, lines", [
    ("problem: poisson\nsource: 1\nsource: 2\n", "source", (2, 3)),
    ("problem: poisson\nmesh:\n  h: 0.1\n  geometry: unit_square\n  h: 0.2\n", "h", (3, 5)),
], ids=["top-level", "nested"])
def test_duplicate_yaml_key_is_refused_naming_key_and_both_lines(tmp_path, capsys, text, key, lines):
    case = tmp_path / "case.yaml"
    case.write_text(text)
    before = set(tmp_path.iterdir())
    assert main(["solve", str(case)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert f"key {key!r} given twice" in err[0]
    assert f"lines {lines[0]} and {lines[1]}" in err[0]
    assert set(tmp_path.iterdir()) == before


def test_yaml_anchor_merge_keys_are_not_duplicates(tmp_path):
    from femkit.case.load import read_yaml

    p = tmp_path / "a.yaml"
    p.write_text("base: &b {h: 0.1}\nmesh:\n  <<: *b\n  geometry: unit_square\n")
    assert read_yaml(p)["mesh"] == {"h": 0.1, "geometry": "unit_square"}


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


@pytest.fixture(params=[0o022, 0o077, 0o002], ids=["umask022", "umask077", "umask002"])
def umask(request):
    old = os.umask(request.param)
    try:
        yield request.param
    finally:
        os.umask(old)


def test_atomic_files_get_the_umask_mode(tmp_path, umask):
    text = atomic_write_text(tmp_path / "a.json", "{}")
    with atomic_path(tmp_path / "b.png") as tmp:
        tmp.write_bytes(b"x")
    plain = tmp_path / "plain.txt"
    plain.write_text("x")  # what open() gives under this umask
    assert _mode(text) == _mode(tmp_path / "b.png") == _mode(plain) == 0o666 & ~umask


def test_every_output_file_of_a_run_has_the_umask_mode(tmp_path, umask, capsys):
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump(SMALL))
    assert main(["solve", str(case)]) == 0
    files = [p for p in (tmp_path / "out").rglob("*") if p.is_file()]
    assert {p.name for p in files} >= {"result.json", "solution.vtu"}
    assert {p.name: _mode(p) for p in files} == {p.name: 0o666 & ~umask for p in files}


ROPE = {
    "problem": "mass_spring",
    "system": {"type": "rope", "n": 6, "length": 1.0, "k": 500.0, "total_mass": 0.6},
    "forces": {"gravity": 9.81},
    "integrator": {"method": "velocity_verlet"},
    "dt": 1e-3,
    "t_end": 0.05,
    "output": {"dir": "out"},
}


@pytest.mark.parametrize("integrator, pieces", [
    ({"method": "fast_mass_spring", "options": {"iters": 10}},
     ["integrator.options", "unknown option 'iters'", "did you mean 'iterations'", "valid options: ",
      "chebyshev"]),
    ({"method": "newmark", "options": {"beta": "fast"}},
     ["integrator.options", "option 'beta' must be a number", "'fast'"]),
    ({"method": "fast_mass_spring", "options": {"iterations": 2.5}},
     ["option 'iterations' must be an integer", "2.5"]),
    ({"method": "newton", "options": {"matrix_free": "yes"}},
     ["option 'matrix_free' must be true or false"]),
], ids=["unknown-option", "string-for-number", "float-for-int", "string-for-bool"])
def test_bad_integrator_option_names_the_option_and_the_valid_ones(tmp_path, capsys, integrator, pieces):
    data = dict(ROPE, integrator=integrator)
    case = tmp_path / "scene.yaml"
    case.write_text(yaml.safe_dump(data))
    assert main(["solve", str(case)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "__init__" not in err, err
    for piece in pieces:
        assert piece in err, (piece, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.yaml"]


ROOT = Path(__file__).parents[2]


@pytest.mark.parametrize("argv", [
    ["solve", str(ROOT / "cases" / "poisson_unit_square.yaml")],
    ["solve", str(ROOT / "cases" / "scenes" / "rope_pendulum.yaml")],
    ["study", str(ROOT / "studies" / "poisson_convergence.yaml"), "--quick"],
], ids=["poisson", "scene", "study"])
def test_unwritable_output_is_refused_before_any_work(argv, capsys):
    """/proc accepts no new entries, even for root (for whom chmod changes nothing)."""
    import time

    out = "/proc/femkit-no-such-dir/out"
    t0 = time.perf_counter()
    code = main([*argv, "--output", out])
    elapsed = time.perf_counter() - t0
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "cannot be written" in lines[0] and out in lines[0], err
    assert elapsed < 5.0  # refused at once, not after the solve / simulation / study


def test_fmg_summary_states_its_criterion_not_a_residual_tolerance(tmp_path, capsys):
    data = yaml.safe_load((ROOT / "cases" / "poisson_fmg_unit_square.yaml").read_text())
    data["mesh"]["refine"] = 3
    data["output"] = {"dir": "out", "vtu": False, "plot": False}
    case = tmp_path / "fmg.yaml"
    case.write_text(yaml.safe_dump(data))
    assert main(["solve", str(case)]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("solver"))
    assert "converged to the discretisation error" in line and "V-cycles" in line
    assert "tolerance" not in line and "not the criterion" in line


@pytest.mark.parametrize("case", ["poisson_unit_square.yaml", "scenes/rope_pendulum.yaml"],
                         ids=["poisson", "scene"])
def test_python_api_is_quiet_unless_asked(case, capsys, tmp_path):
    from femkit.case import load_case

    c = load_case(ROOT / "cases" / case, mesh={"h": 0.2}) if "poisson" in case else \
        load_case(ROOT / "cases" / case, t_end=0.05)
    c.run(write=False)
    assert capsys.readouterr().out == ""
    c.run(write=False, quiet=False)
    assert capsys.readouterr().out.strip() != ""
