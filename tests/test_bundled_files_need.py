"""Every bundled case, scene and study runs with README's first install (``pip install -e .``),
or says in its first line which optional extra it needs; without that extra it stops in one line
naming how to install it (exit 2, nothing written).

"The default install" is simulated in-process: the optional solver packages (scikit-sparse /
CHOLMOD, cholespy, petsc4py, mpi4py) cannot be imported (``sys.modules[name] = None``)."""

import sys
from pathlib import Path

import pytest
import yaml

from femkit.cli import main

ROOT = Path(__file__).parents[1]
BUNDLED = sorted([*ROOT.glob("cases/**/*.yaml"), *ROOT.glob("studies/*.yaml")])
#: what `femkit solve` / `femkit study` runs: cases/stress/*.yaml are the stress study's members
RUNNABLE = [p for p in BUNDLED if p.parent.name != "stress"]
#: solver names / engines that need an optional extra, and the extra's name
EXTRAS = {"cholesky": "femkit[cholesky]", "cholespy": "femkit[fast]", "pardiso": "femkit[pardiso]",
          "petsc": "install-petsc.sh"}
#: the importable packages of those extras
OPTIONAL_MODULES = ("sksparse", "sksparse.cholmod", "cholespy", "petsc4py", "mpi4py")


def _id(path: Path) -> str:
    return str(path.relative_to(ROOT))


@pytest.fixture
def default_install(monkeypatch):
    """The optional solver packages cannot be imported (`import sksparse` raises ImportError)."""
    for name in OPTIONAL_MODULES:
        monkeypatch.setitem(sys.modules, name, None)


def _values(node):
    if isinstance(node, dict):
        for k, v in node.items():
            yield str(k)
            yield from _values(v)
    elif isinstance(node, list):
        for v in node:
            yield from _values(v)
    else:
        yield str(node)


def _needs_data(data) -> set[str]:
    """The extras a file's data asks for in its values (comments do not count)."""
    words = set(_values(data))
    return {extra for name, extra in EXTRAS.items() if name in words}


def _needs(path: Path) -> set[str]:
    return _needs_data(yaml.safe_load(path.read_text()))


def _command(path: Path) -> str:
    return "study" if path.parent.name == "studies" else "solve"


def test_bundled_files_were_found_and_the_scan_sees_an_extra():
    assert len(BUNDLED) >= 20 and len(RUNNABLE) >= 20
    # the checks below are not vacuous: a solver spec naming an extra is seen
    assert _needs_data({"linear_solver": {"method": "cholesky"}}) == {"femkit[cholesky]"}
    assert _needs_data({"solver": {"method": "cholesky", "options": {"engine": "pardiso"}}}) == {
        "femkit[cholesky]", "femkit[pardiso]"}


@pytest.mark.parametrize("path", BUNDLED, ids=_id)
def test_a_file_that_needs_an_extra_says_so_in_its_first_line(path):
    first = path.read_text().splitlines()[0]
    for extra in _needs(path):
        assert first.startswith("#") and extra in first, (path.name, first)


@pytest.mark.parametrize("path", RUNNABLE, ids=_id)
def test_every_bundled_file_plans_with_the_default_install(path, default_install, capsys):
    """``--dry-run`` (load, validate, price) exits 0, or the file's first line says what it needs.
    A dry run solves nothing, so a solver of an extra is caught by the scan above and by the
    quick run below."""
    code = main([_command(path), str(path), "--dry-run"])
    err = capsys.readouterr().err
    if code != 0:
        first = path.read_text().splitlines()[0]
        assert first.startswith("#") and "need" in first.lower(), (code, err, first)


def test_the_cloth_study_runs_with_the_default_install(default_install, tmp_path):
    """The study of the implicit cloth methods, whose linear solves are the point, runs quick
    without CHOLMOD (SuperLU)."""
    path = ROOT / "studies" / "cloth_work_precision.yaml"
    assert main(["study", str(path), "--quick", "--quiet", "--output", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "runs.csv").is_file()


@pytest.mark.parametrize("sets, install", [
    (["linear_solver.method=cholesky"], "bash scripts/install-cholesky.sh"),
    (["linear_solver.method=cholesky", "linear_solver.options.engine=cholespy"], "femkit[fast]"),
], ids=["no-scikit-sparse", "no-cholespy"])
def test_without_the_extra_the_run_stops_in_one_line_naming_the_install(sets, install, default_install,
                                                                       tmp_path, capsys):
    path = ROOT / "studies" / "cloth_work_precision.yaml"
    code = main(["study", str(path), "--quick", "--output", str(tmp_path / "out"),
                 *[a for s in sets for a in ("--set", s)]])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert install in err[0]
    assert not (tmp_path / "out").exists()
