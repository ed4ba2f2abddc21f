"""No femkit command may delete files it did not write: scenes and studies, like Poisson cases,
refuse an output directory that holds other files (e.g. ``--output .``) before running, and
replace only an earlier run of their own kind."""

from pathlib import Path

import pytest

from femkit.cli import main

ROOT = Path(__file__).resolve().parents[2]
COMMANDS = {
    "scene": ["solve", str(ROOT / "cases/scenes/rope_pendulum.yaml")],
    # one solver, one rule, no peer reference: what is tested is the directory, not the sweep
    "study": ["study", str(ROOT / "studies/poisson_convergence.yaml"), "--quick", "--no-progress",
              "--set", "solvers=[{method: direct}]", "--set", "quadrature=[barycentric]",
              "--set", "reference=none"],
}


@pytest.mark.parametrize("kind", COMMANDS)
def test_refuses_a_directory_with_user_files_and_leaves_it_untouched(kind, tmp_path, capsys):
    mine = tmp_path / "project"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me")
    assert main([*COMMANDS[kind], "-o", str(mine)]) == 2
    err = capsys.readouterr().err
    assert "is not a femkit output" in err and err.count("\n") == 1
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]
    assert (mine / "notes.txt").read_text() == "keep me"


@pytest.mark.parametrize("kind", COMMANDS)
def test_replaces_its_own_earlier_run(kind, tmp_path):
    out = tmp_path / "out"
    assert main([*COMMANDS[kind], "-o", str(out), "-q"] if kind == "scene" else
                [*COMMANDS[kind], "-o", str(out)]) == 0
    first = sorted(p.name for p in out.iterdir())
    assert main([*COMMANDS[kind], "-o", str(out), "-q"] if kind == "scene" else
                [*COMMANDS[kind], "-o", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == first
