"""Study progress off a terminal counts what the summary counts (issue 17: '9 runs' in the
progress, 426 in the summary) and a short study prints one progress line, not ten."""

import re
from pathlib import Path

import pytest

from femkit.cli import main

STUDIES = Path(__file__).resolve().parents[2] / "studies"


@pytest.mark.parametrize("name", ["poisson_convergence", "cloth_work_precision",
                                  "dynamics_work_precision"])
def test_progress_counts_the_summarys_runs(tmp_path, capsys, name):
    assert main(["study", str(STUDIES / f"{name}.yaml"), "--quick", "-o", str(tmp_path / "r")]) == 0
    captured = capsys.readouterr()
    runs = int(re.search(r"'[^']+': (\d+) runs in ", captured.out).group(1))
    lines = captured.err.strip().splitlines()
    assert len(lines) <= 2, lines  # a study of seconds: its last line (and maybe one more)
    assert re.search(rf": 100% \({runs}/{runs} runs\), elapsed ", lines[-1]), (runs, lines)
