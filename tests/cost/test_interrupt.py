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
