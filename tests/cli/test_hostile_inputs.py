"""Hostile inputs that once got through (issue 30): each is refused cleanly.

A clean refusal: exit code 2, ONE line on stderr naming the problem, nothing written next to the
input, and in well under 5 s (each of these once ran for minutes, hung, or ended in a
traceback). Every entry of :data:`CASES` builds its input files in a fresh directory and says
which command runs them and which words the one line must hold.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared case
from _small import SMALL  # noqa: E402

from femkit.cli import main

ROOT = Path(__file__).resolve().parents[2]


def _alias_bomb(d: Path) -> list[str]:
    """Ten levels of ten aliases: 10**10 values once expanded, 400 bytes of text."""
    lines = ["problem: poisson", "a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 10)]
    (d / "case.yaml").write_text("\n".join(lines) + "\n")
    return ["solve", str(d / "case.yaml")]


def _alias_cycle(d: Path) -> list[str]:
    (d / "case.yaml").write_text("problem: poisson\na: &a [1, *a]\n")
    return ["solve", str(d / "case.yaml")]


def _huge_file(d: Path) -> list[str]:
    """Far more text than a case file holds (the 50 MB one was silent for minutes)."""
    with open(d / "case.yaml", "w") as fh:
        fh.write("problem: poisson\n")
        for i in range(0, 300_000, 1000):
            fh.write("".join(f"k{j}: {j}\n" for j in range(i, i + 1000)))
    return ["solve", str(d / "case.yaml")]


def _study_alias_bomb(d: Path) -> list[str]:
    _alias_bomb(d)
    text = (d / "case.yaml").read_text().replace("problem: poisson", "kind: poisson_convergence")
    (d / "case.yaml").unlink()
    (d / "study.yaml").write_text(text)
    return ["study", str(d / "study.yaml")]


def _case_symlink_loop(d: Path) -> list[str]:
    os.symlink("case.yaml", d / "case.yaml")
    return ["solve", str(d / "case.yaml")]


def _mesh_symlink_loop(d: Path) -> list[str]:
    os.symlink("loop.msh", d / "loop.msh")
    data = dict(SMALL, mesh={"file": "loop.msh"})
    (d / "case.yaml").write_text(yaml.safe_dump(data))
    return ["solve", str(d / "case.yaml")]


def _study_nan(d: Path) -> list[str]:
    """``t_end: .nan`` in a springs_vs_elements study (once: ValueError converting NaN)."""
    text = (ROOT / "studies" / "springs_vs_elements.yaml").read_text()
    text = text.replace("dt: 0.05, t_end: 0.6", "dt: 0.05, t_end: .nan")
    assert ".nan" in text
    (d / "study.yaml").write_text(text)
    return ["study", str(d / "study.yaml"), "--quick"]


def _case_inf(d: Path) -> list[str]:
    data = dict(SMALL, solver={"method": "cg", "rtol": float("inf")})
    (d / "case.yaml").write_text(yaml.safe_dump(data))
    return ["solve", str(d / "case.yaml")]


#: id -> (builder, words the one line holds)
CASES = {
    "yaml-alias-bomb": (_alias_bomb, ["case.yaml", "aliases", "200,000 values"]),
    "yaml-alias-cycle": (_alias_cycle, ["case.yaml", "alias", "inside the node it names"]),
    "yaml-file-too-large": (_huge_file, ["case.yaml", "bytes", "larger than the 2,000,000"]),
    "study-yaml-alias-bomb": (_study_alias_bomb, ["study.yaml", "aliases"]),
    "case-file-symlink-loop": (_case_symlink_loop, ["case.yaml", "symbolic link", "loop"]),
    "mesh-file-symlink-loop": (_mesh_symlink_loop, ["mesh.file", "symbolic link loop", "loop.msh"]),
    "study-t_end-nan": (_study_nan, ["quick.scenes.hanging_beam.t_end", "finite number", ".nan"]),
    "case-rtol-inf": (_case_inf, ["solver.rtol", "finite number", ".inf"]),
}


@pytest.mark.parametrize("name", list(CASES))
def test_hostile_input_is_refused_in_one_line(name, tmp_path, capsys):
    build, words = CASES[name]
    argv = build(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    start = time.perf_counter()
    code = main(argv)
    took = time.perf_counter() - start
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for word in words:
        assert word in err, (word, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert took < 5.0, took
