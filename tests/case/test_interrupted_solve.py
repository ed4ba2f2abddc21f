"""A stop request during an iterative Poisson solve writes the last iterate, marked interrupted."""

import json
import signal

from femkit.case import load_case
from femkit.interrupt import StopFlag


class StopAfterChecks(StopFlag):
    """False the first ``n`` times it is looked at, then set (as SIGTERM); it is looked at after
    the mesh, assembly and boundary stages, then once per solver iteration."""

    def __init__(self, n):
        super().__init__()
        self.left = n

    def __bool__(self):
        self.left -= 1
        if self.left < 0 and self.signum is None:
            self.request(signal.SIGTERM)
        return self.signum is not None


def test_interrupted_cg_writes_the_last_iterate(tmp_path):
    case = load_case("cases/poisson_unit_square.yaml", solver={"method": "cg", "preconditioner": None, "rtol": 1e-12},
                     output={"dir": str(tmp_path / "out")})
    case = case.with_options(stop=StopAfterChecks(3 + 4))  # set during iteration 5
    result = case.run(quiet=True)
    assert result.interrupted == "SIGTERM"
    assert result.solve.reason == "interrupted" and result.solve.iterations == 5
    assert not result.converged and result.solve.true_residual > result.solve.tolerance
    data = json.loads((tmp_path / "out" / "result.json").read_text())
    assert data["interrupted"] is True and data["solver"]["reason"] == "interrupted"
    assert (tmp_path / "out" / "solution.vtu").is_file()


def test_stop_between_stages_writes_nothing(tmp_path):
    import pytest

    from femkit.interrupt import Interrupted

    case = load_case("cases/poisson_unit_square.yaml", output={"dir": str(tmp_path / "out")})
    case = case.with_options(stop=StopAfterChecks(1))  # set when the assembly stage ends (second look)
    with pytest.raises(Interrupted, match="interrupted by SIGTERM after the assembly stage"):
        case.run(quiet=True)
    assert not (tmp_path / "out").exists()
