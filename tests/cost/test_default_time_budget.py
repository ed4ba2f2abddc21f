"""The default time budget (issue 17): a run priced beyond
:data:`femkit.cost.DEFAULT_TIME_BUDGET` (one hour) is refused with the estimate in the message,
unless the file raises the budget (``limits: {time: ...}``) or ``--force`` is given."""

import subprocess
import sys

import pytest
import yaml

from cost_probe import child_env
from femkit.errors import BudgetExceededError


def _rope(tmp_path, **over):
    scene = {"problem": "mass_spring", "name": "slow",
             "system": {"type": "rope", "n": 10, "length": 1.0, "k": 100.0, "total_mass": 1.0},
             "forces": {"gravity": 9.81}, "integrator": "symplectic_euler",
             "dt": 1.0e-9, "t_end": 10, "output": {"frames": 20, "dir": "out"}}
    scene.update(over)
    path = tmp_path / "slow.yaml"
    path.write_text(yaml.safe_dump(scene))
    return path


def test_cli_refuses_a_run_priced_beyond_the_default_budget(tmp_path):
    path = _rope(tmp_path)
    out = subprocess.run([sys.executable, "-m", "femkit", "solve", str(path)], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120, env=child_env())
    lines = out.stderr.strip().splitlines()
    assert out.returncode == 2 and len(lines) == 1, out.stderr
    msg = lines[0]
    assert msg.startswith("femkit: error: slow: ") and "predicted time " in msg
    assert "exceeds the default time budget 1 h" in msg and "1e+10 steps" in msg
    assert "--force" in msg and "limits: {time: ...}" in msg
    assert not (tmp_path / "out").exists()


def test_raised_budget_or_force_lets_it_through(tmp_path):
    from femkit import load_case
    from femkit.case.budget import check_case

    with pytest.raises(BudgetExceededError) as err:
        check_case(load_case(_rope(tmp_path)))
    assert err.value.what == "time" and err.value.predicted > 3600.0
    # raised far above the estimate (a first batch of steps on a busy machine varies 10x and more)
    raised = load_case(_rope(tmp_path, limits={"time": "100000d"}))
    assert check_case(raised).options.plan.seconds > 3600.0  # priced as before, now within the raised budget
    said = []
    plan = check_case(load_case(_rope(tmp_path)), force=True, echo=said.append).options.plan
    assert plan.seconds > 3600.0 and len(said) == 1 and "default time budget" in said[0]
    assert said[0].endswith("(--force given)")


def test_the_budget_has_one_home(tmp_path, monkeypatch):
    """Lowering ``DEFAULT_TIME_BUDGET`` in its one place refuses an ordinary run."""
    import femkit.cost.budget as budget
    from femkit import load_case
    from femkit.case.budget import check_case

    short = _rope(tmp_path, dt=1e-3, t_end=2.0)
    assert check_case(load_case(short)).options.plan.seconds < 3600.0
    monkeypatch.setattr(budget, "DEFAULT_TIME_BUDGET", 1e-6)
    with pytest.raises(BudgetExceededError, match="default time budget"):
        check_case(load_case(short))
