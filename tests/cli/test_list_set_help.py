"""The newcomer's command line: ``femkit list`` (read from the registries), ``--set KEY=VALUE``
(through the file's own validation) and help texts that list what the registries hold."""

import json
import re
import sys
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared case
from _small import SMALL  # noqa: E402

from femkit.catalog import GROUPS, entries
from femkit.cli import build_parser, main, parse_sets
from femkit.errors import InputError



def _registry(group):
    return GROUPS[group][1]()


LIST_GROUPS = tuple(GROUPS)


def test_list_groups_of_the_parser_are_the_catalog_groups(capsys):
    """The groups ``femkit list --help`` names are the catalog's, in its order (no second list),
    and each one's singular resolves to it."""
    from femkit.cli.parser import _list_group

    with pytest.raises(SystemExit):
        build_parser().parse_args(["list", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    named = text.split("with one line on what it is: ")[1].split(" (default: all)")[0]
    assert tuple(named.split(", ")) == LIST_GROUPS and len(LIST_GROUPS) >= 10
    assert [_list_group(g) for g in ("geometry", "solver", "study", "material")] == [
        "geometries", "solvers", "studies", "materials"]


@pytest.mark.parametrize("group", LIST_GROUPS)
def test_list_prints_every_registered_name_of_a_group(group, capsys):
    assert main(["list", group]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"{group} (")
    listed = [line.split()[0] for line in out[1:] if line.strip()]
    assert listed == sorted(_registry(group).names()) and listed


def test_a_newly_registered_solver_and_geometry_appear(capsys):
    from femkit.mesh.geometries import GEOMETRIES, register_geometry
    from femkit.solvers.registry import SOLVERS

    def brand_new_solver(A, b, **kw):
        """A solver registered by this test only."""

    SOLVERS.register("zz_test_solver", brand_new_solver)
    register_geometry("zz_test_strip", measure=lambda: (1.0, 4.0),
                      boundary_tags=("boundary",), cell_tags=("domain",))(lambda h: None)
    try:
        assert main(["list", "solver", "geometries"]) == 0
        out = capsys.readouterr().out
        assert re.search(r"^  zz_test_solver +A solver registered by this test only\.$", out, re.M)
        assert re.search(r"^  zz_test_strip +2D; parameters: none; tags: boundary, domain$", out, re.M)
    finally:
        SOLVERS.remove("zz_test_solver")
        GEOMETRIES.remove("zz_test_strip")
    assert main(["list", "solvers"]) == 0
    assert "zz_test_solver" not in capsys.readouterr().out


def test_list_all_groups_and_an_unknown_group(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert all(f"\n{g} (" in "\n" + out for g in LIST_GROUPS)
    assert main(["list", "solverz"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown group 'solverz'" in err[0] and "preconditioners" in err[0]


def test_every_entry_has_a_one_line_description():
    for group in LIST_GROUPS:
        for name, text in entries(group):
            assert "\n" not in text and "``" not in text and ":func:" not in text, (group, name)


# ----------------------------------------------------------------------------- --set

@pytest.fixture
def case(tmp_path):
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(SMALL))
    return path


def test_set_changes_the_case_as_the_file_would(case, capsys):
    assert main(["solve", str(case), "--quiet", "--set", "mesh.h=0.125",
                 "--set", "solver.rtol=1e-6", "--set", "output.dir=other"]) == 0
    result = json.loads((case.parent / "other" / "result.json").read_text())
    edited = dict(SMALL, mesh={"geometry": "unit_square", "h": 0.125},
                  solver={"method": "cg", "rtol": 1e-6}, output={"dir": "other", "vtu": False})
    (case.parent / "edited.yaml").write_text(yaml.safe_dump(edited))
    assert main(["solve", str(case.parent / "edited.yaml"), "--quiet"]) == 0
    same = json.loads((case.parent / "other" / "result.json").read_text())
    for key in ("mesh", "solver"):
        assert {k: v for k, v in result[key].items() if "time" not in k} == \
               {k: v for k, v in same[key].items() if "time" not in k}


@pytest.mark.parametrize("item, words", [
    ("mesh.hh=0.02", ["mesh.hh", "unknown key", "valid keys", "geometry", "h"]),
    ("mesh.h=abc", ["mesh.h", "number"]),
    ("mesh.h=-1", ["mesh.h", "> 0"]),
    ("solver.method=bicg", ["solver.method", "unknown solver 'bicg'", "valid solvers", "pcg"]),
    ("mesh.h", ["--set 'mesh.h'", "KEY=VALUE"]),
    ("mesh..h=1", ["--set 'mesh..h=1'", "KEY=VALUE"]),
    ("mesh.h=[", ["--set 'mesh.h=['", "not valid YAML"]),
], ids=["typo", "not-a-number", "negative", "unknown-solver", "no-equals", "empty-part", "bad-yaml"])
@pytest.mark.parametrize("command", ["solve", "check"])
def test_a_bad_set_is_one_line_exit_2_nothing_written(case, capsys, item, words, command):
    before = set(case.parent.iterdir())
    assert main([command, str(case), "--set", item]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert all(w in err[0] for w in words), err[0]
    assert set(case.parent.iterdir()) == before


def test_set_on_a_study_goes_through_the_study_schema(tmp_path, capsys):
    study = tmp_path / "s.yaml"
    problem = {k: v for k, v in SMALL.items() if k not in ("problem", "output", "solver")}
    problem["exact"] = {"u": "0"}
    study.write_text(yaml.safe_dump({"kind": "poisson_convergence", "problem": problem,
        "levels": {"h0": 0.5, "count": 2}, "solvers": [{"method": "direct"}], "repeats": 1}))
    assert main(["study", str(study), "--set", "levls.count=3", "--dry-run"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "levls" in err[0] and "did you mean 'levels'" in err[0]
    assert main(["study", str(study), "--set", "levels.count=3", "--dry-run"]) == 0
    assert "3 levels" in capsys.readouterr().out


def test_parse_sets_reads_values_as_yaml_scalars():
    assert parse_sets(["a.b=1", "c=1e-3", "d=yes please", "e=", "f=[1, 2]"]) == {
        "a__b": 1, "c": 1e-3, "d": "yes please", "e": "", "f": [1, 2]}
    with pytest.raises(InputError):
        parse_sets(["=1"])


# ----------------------------------------------------------------------------- help

def _help(argv, capsys) -> str:
    with pytest.raises(SystemExit) as info:
        main([*argv, "--help"])
    assert info.value.code == 0
    return capsys.readouterr().out


def _section(text: str, title: str) -> list[str]:
    """The indented lines under ``title:`` up to the next blank line."""
    lines = text.splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith(title))
    out = []
    for line in lines[start + 1:]:
        if not line.strip():
            break
        out.append(line)
    return out


def test_study_help_lists_every_registered_kind_exit_codes_and_examples(capsys):
    from femkit.kinds import KINDS

    text = _help(["study"], capsys)
    kinds = [line.split()[0] for line in _section(text, "study kinds")]
    assert kinds == KINDS.names("kind") and len(kinds) >= 5
    codes = [line.split()[0] for line in _section(text, "exit codes") if line[2:3] != " "]
    assert codes == ["0", "2", "130,"]
    examples = _section(text, "examples")
    assert examples and all(l.strip().startswith("femkit study studies/") for l in examples)


def test_check_help_has_its_own_epilog_without_output_files(capsys):
    text = _help(["check"], capsys)
    epilog = text[text.index("exit codes"):]
    assert "writes no files" in epilog
    assert "result.json" not in epilog and "--output" not in text
    assert all(l.strip().startswith("femkit check ") for l in _section(epilog, "examples"))


def test_solve_help_documents_exit_codes_and_the_second_ctrl_c(capsys):
    text = _help(["solve"], capsys)
    codes = [line.split()[0] for line in _section(text, "exit codes") if line[2:3] != " "]
    assert codes == ["0", "1", "2", "130,"]
    assert "second Ctrl-C" in text and "--set KEY=VALUE" in text


def test_list_help_names_every_group(capsys):
    text = _help(["list"], capsys)
    assert all(g in " ".join(text.split()) for g in LIST_GROUPS)
