"""Stop flags: signals set a flag; simulate() stops between steps and keeps the trajectory."""

import os
import signal

import numpy as np

from femkit.dynamics.simulate import simulate
from femkit.dynamics.topology import single_spring
from femkit.interrupt import StopFlag, exit_code, stop_on_signals


def test_sigterm_sets_the_flag_instead_of_killing():
    before = signal.getsignal(signal.SIGTERM)
    with stop_on_signals() as flag:
        os.kill(os.getpid(), signal.SIGTERM)
        assert flag and flag.name == "SIGTERM" and exit_code(flag) == 143
    assert signal.getsignal(signal.SIGTERM) is before


def test_sigint_exit_code():
    flag = StopFlag()
    flag.request(signal.SIGINT)
    assert exit_code(flag) == 130


class StopAfter:
    name = "SIGTERM"

    def __init__(self, n):
        self.n, self.calls = n, 0

    def __call__(self):
        self.calls += 1
        return self.calls > self.n


def test_simulate_stops_between_steps_and_keeps_what_it_computed():
    system = single_spring()
    full = simulate(system, "verlet", 1e-3, 1.0, record_every=100)
    part = simulate(system, "verlet", 1e-3, 1.0, record_every=100, stop=StopAfter(250))
    assert part.interrupted and not part.completed and part.steps == 250
    assert "interrupted by SIGTERM at step 250 of 1000" in part.reason
    # frames at steps 0, 100, 200 as in the full run, then the state at the stop
    np.testing.assert_allclose(part.times, [0.0, 0.1, 0.2, 0.25])
    np.testing.assert_array_equal(part.x[:3], full.x[:3])
    assert part.summary()["interrupted"] is True
    assert np.isfinite(part.energies["total"]).all()


def test_signal_from_outside_stops_a_simulation_cleanly(tmp_path):
    """SIGTERM sent by this test to a process in a long simulate(): it keeps the trajectory
    so far, reports progress lines on its (non-terminal) stderr, and exits with 143."""
    import json
    import subprocess
    import sys
    import time

    script = tmp_path / "run.py"
    script.write_text(
        "import json, sys\n"
        "from femkit.dynamics.simulate import simulate\n"
        "from femkit.dynamics.topology import cloth_grid\n"
        "from femkit.interrupt import exit_code, stop_on_signals\n"
        "from femkit.progress import Progress\n"
        "system = cloth_grid(8, 8, 1.0, 1.0, k_structural=100.0, total_mass=0.5)\n"
        "with stop_on_signals() as flag:\n"
        "    bar = Progress(10**7, 'cloth', every_seconds=0.2)\n"
        "    print('started', flush=True)\n"
        "    traj = simulate(system, 'symplectic_euler', 1e-4, 1e3, record_every=500, stop=flag,\n"
        "                    progress=bar, check_stability=False)\n"
        "print(json.dumps(traj.summary()), flush=True)\n"
        "sys.exit(exit_code(flag) if flag else 0)\n")
    from cost_probe import child_env

    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=child_env())
    assert proc.stdout.readline().strip() == "started"
    time.sleep(1.0)
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 143
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["interrupted"] is True and summary["completed"] is False
    assert summary["steps"] > 0 and summary["recorded"] >= 2
    assert "interrupted by SIGTERM" in summary["reason"]
    lines = [ln for ln in err.splitlines() if ln.startswith("cloth: ")]
    assert len(lines) >= 2 and "remaining ~" in lines[0]
    assert lines[-1].endswith("interrupted by SIGTERM")
