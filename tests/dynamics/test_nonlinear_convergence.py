"""Iterative implicit steps (newton, newmark, variational_symplectic) that stop at
max_iterations without meeting their tolerance must say so: a counter in ctx.stats and one
warning per run, never a silent "step done"."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from femkit.dynamics.integrators import StepContext, get_integrator
from femkit.dynamics.integrators.base import NonlinearConvergenceWarning
from femkit.dynamics.system import MassSpringSystem
from femkit.dynamics.topology import cloth_grid
from femkit.errors import StabilityWarning


def _compressed_cloth(scale=0.4):
    """A cloth squeezed to ``scale`` of its rest size (0.4: strongly nonlinear buckling)."""
    c = cloth_grid(5, 5, 1.0, 1.0, k_structural=1e4, k_shear=1e3, k_bending=1e2,
                   total_mass=1.0, pinned=[])
    x0 = scale * c.x0 + 1e-3 * np.random.default_rng(0).standard_normal(c.x0.shape)
    return MassSpringSystem(x0, c.mass, c.springs, c.k, rest=c.rest, pinned=[0])


def _run(name, steps, scale=0.4, dt=0.05, **opts):
    s = _compressed_cloth(scale)
    integ = get_integrator(name, **opts)
    ctx = StepContext()
    st = integ.start(s, s.x0, s.v0, 0.0, dt, ctx)
    for _ in range(steps):
        st = integ.step(s, st, dt, ctx)
    return ctx


@pytest.mark.parametrize("name", ["newton", "newmark", "variational_symplectic"])
def test_step_stopped_at_max_iterations_is_reported(name):
    with pytest.warns(NonlinearConvergenceWarning, match=rf"{name}.*max_iterations = 2"):
        ctx = _run(name, 3, max_iterations=2)
    assert ctx.stats["unconverged_steps"] == 3
    assert issubclass(NonlinearConvergenceWarning, StabilityWarning)  # lands in result.json


@pytest.mark.parametrize("name", ["newton", "newmark", "variational_symplectic"])
def test_converged_steps_report_nothing(name):
    with warnings.catch_warnings():
        warnings.simplefilter("error", NonlinearConvergenceWarning)
        ctx = _run(name, 3, scale=1.1, dt=0.003, max_iterations=50)  # stretched
    assert ctx.stats.get("unconverged_steps", 0) == 0
    assert max(ctx.stats["newton_iterations"]) > 1  # a nonlinear step, not a trivial one
