"""Every bundled case, scene and study runs with README's first install, or says in its first
line which optional extra it needs; without that extra it stops in one line naming how to
install it (exit 2, nothing written)."""

import re
import sys
from pathlib import Path

import pytest
import yaml

from femkit.cli import main

ROOT = Path(__file__).parents[1]
BUNDLED = sorted([*ROOT.glob("cases/**/*.yaml"), *ROOT.glob("studies/*.yaml")])
#: solver names / engines that need an optional extra, and the extra's name
EXTRAS = {"cholesky": "femkit[cholesky]", "pardiso": "femkit[pardiso]", "petsc": "install-petsc.sh"}


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


def _needs(path: Path) -> set[str]:
    """The extras a bundled file asks for in its values (comments do not count)."""
    words = set(_values(yaml.safe_load(path.read_text())))
    return {extra for name, extra in EXTRAS.items() if name in words}


def test_bundled_files_were_found():
    assert len(BUNDLED) >= 20
    assert any(_needs(p) for p in BUNDLED)  # the check below is not vacuous


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: str(p.relative_to(ROOT)))
def test_a_file_that_needs_an_extra_says_so_in_its_first_line(path):
    first = path.read_text().splitlines()[0]
    for extra in _needs(path):
        assert first.startswith("#") and extra in first, (path.name, first)


@pytest.mark.parametrize("path", [p for p in BUNDLED if "femkit[cholesky]" in _needs(p)],
                         ids=lambda p: p.name)
def test_without_cholmod_the_run_stops_in_one_line_naming_the_install(path, tmp_path, capsys,
                                                                     monkeypatch):
    monkeypatch.setitem(sys.modules, "sksparse", None)  # `import sksparse` now fails
    monkeypatch.setitem(sys.modules, "sksparse.cholmod", None)
    command = "study" if path.parent.name == "studies" else "solve"
    code = main([command, str(path), "--output", str(tmp_path / "out"), *(["--quick"] if command == "study" else [])])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert re.search(r"install-cholesky\.sh", err[0]) and "cholesky" in err[0]
    assert not (tmp_path / "out").exists()
