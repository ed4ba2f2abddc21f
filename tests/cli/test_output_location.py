"""Where `femkit solve` writes: it never replaces what it did not write itself.

The output directory is replaced atomically by a new run, but only when it is a previous
femkit run (or empty): pointing ``--output`` at ``.`` or at a regular file must be refused as
bad input (exit 2, nothing touched), not move the user's files away and delete them.
"""

import yaml

from femkit.cli import main

SMALL = {
    "problem": "poisson",
    "mesh": {"geometry": "unit_square", "h": 0.5},
    "source": "1",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
    "solver": {"method": "direct"},
}


def _case(path, **output):
    data = dict(SMALL, output=dict(output, vtu=False)) if output else dict(SMALL)
    path.write_text(yaml.safe_dump(data))
    return path


def _one_line_error(capsys, *pieces):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("femkit: error: "), err
    for piece in pieces:
        assert piece in err[0], (piece, err[0])


def test_output_into_the_case_directory_keeps_the_users_files(tmp_path, capsys, monkeypatch):
    proj = tmp_path / "proj"
    proj.mkdir()
    case = _case(proj / "c.yaml")
    (proj / "notes.txt").write_text("precious")
    monkeypatch.chdir(proj)
    assert main(["solve", "c.yaml", "--output", ".", "--quiet"]) == 2
    _one_line_error(capsys, str(proj), "not a femkit output")
    assert (proj / "notes.txt").read_text() == "precious" and case.is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["proj"]  # no temp/old dirs left


def test_output_dir_that_is_a_file_is_bad_input(tmp_path, capsys):
    target = tmp_path / "results"
    target.write_text("a file of the user's")
    case = _case(tmp_path / "c.yaml", dir="results")
    assert main(["solve", str(case), "--quiet"]) == 2
    _one_line_error(capsys, "output.dir", str(target), "not a directory")
    assert target.read_text() == "a file of the user's"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.yaml", "results"]


def test_output_dir_below_a_file_is_bad_input(tmp_path, capsys):
    (tmp_path / "f").write_text("x")
    case = _case(tmp_path / "c.yaml", dir="f/run")
    assert main(["solve", str(case), "--quiet"]) == 2
    _one_line_error(capsys, "output.dir", "not a directory")


def test_previous_run_and_empty_directory_are_replaced(tmp_path, capsys):
    case = _case(tmp_path / "c.yaml", dir="run")
    (tmp_path / "run").mkdir()  # empty: fine
    assert main(["solve", str(case), "--quiet"]) == 0
    (tmp_path / "run" / "stale.txt").write_text("from an older run")
    assert main(["solve", str(case), "--quiet"]) == 0  # a previous femkit run: replaced
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == ["result.json"]
