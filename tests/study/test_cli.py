"""`femkit study` entry points exposed for femkit/cli.py: cli_main and add_parser."""

from __future__ import annotations

import argparse
from pathlib import Path

import yaml

from femkit.study import add_parser, cli_main

ROOT = Path(__file__).resolve().parents[2]


def test_cli_main_runs_quick_study(tmp_path, capsys):
    # the entry point's wiring (the stress study's content is tested in test_stability_study):
    # the smallest sweep a bundled file gives, one solver and one rule
    data = yaml.safe_load((ROOT / "studies" / "poisson_convergence.yaml").read_text())
    data.update(solvers=[{"method": "direct"}], quadrature=["barycentric"], reference="none")
    (tmp_path / "small.yaml").write_text(yaml.safe_dump(data))
    rc = cli_main([str(tmp_path / "small.yaml"), "--quick", "-o", str(tmp_path / "r"), "--no-progress"])
    assert rc == 0
    assert (tmp_path / "r" / "report.html").exists()
    assert "report:" in capsys.readouterr().out


def test_cli_main_bad_input_exit_2_no_output(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("kind: stability\ncasses: []\n")
    assert cli_main([str(bad), "-o", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "casses: unknown key" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "r").exists()


def test_add_parser_wires_subcommand(tmp_path):
    parser = argparse.ArgumentParser(prog="femkit")
    sub = parser.add_subparsers(dest="command")
    add_parser(sub)
    args = parser.parse_args(["study", "x.yaml", "--quick", "-o", "out"])
    assert args.func is cli_main and args.quick and args.output == "out" and args.study == "x.yaml"
