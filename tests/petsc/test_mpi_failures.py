"""A rank that fails never leaves the others hanging (the run ends within the timeout)."""

from __future__ import annotations

import pytest

from conftest import HERE, run_driver

pytestmark = pytest.mark.usefixtures("needs_mpi")


@pytest.mark.parametrize("mode,code,words", [
    ("abort", 1, "rank 1: abort failure on purpose"),
    ("collective", 2, "collective failure on purpose"),
], ids=["one-rank-raises-MPI_Abort", "collective-input-error-exit-2"])
def test_failing_rank_ends_the_run(mode, code, words, tmp_path):
    proc, _ = run_driver(mode, 2, tmp_path, check=False, script=HERE / "failure_driver.py")
    assert proc.returncode == code, proc.stderr
    assert words in proc.stderr
    if mode == "collective":  # ended cleanly: one line, no MPI_Abort
        assert "MPI_ABORT" not in proc.stderr
        assert sum(ln.startswith("femkit: error:") for ln in proc.stderr.splitlines()) == 1
    assert not (tmp_path / f"{mode}-2.npz").exists()
