"""The cloth work-precision engine: errors behave as the methods promise on a small cloth."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.dynamics.forces import Gravity
from femkit.dynamics.topology import cloth_grid
from femkit.dynamics.work_precision import cloth_work_precision, expand_methods
from femkit.errors import InputError, UnknownNameError

pytestmark = pytest.mark.cholmod  # the cholesky solver: optional scikit-sparse


@pytest.fixture(scope="module")
def study():
    cloth = cloth_grid(7, 7, 1.0, 1.0, k_structural=400.0, k_shear=100.0, k_bending=10.0,
                       total_mass=0.5, pinned="top_corners", plane="xy", forces=[Gravity(9.81)])
    methods = [{"family": "fast_mass_spring", "iterations": [1, 5, 20]},
               {"family": "chebyshev", "iterations": [20]},
               {"family": "baraff_witkin"},
               {"family": "newton", "iterations": [1, 3]}]
    return cloth_work_precision(cloth, 0.02, 8, methods, substeps=8)


def _run(study, label):
    return next(r for r in study["runs"] if r.label == label)


def test_solve_error_falls_with_the_work_spent(study):
    fms = [_run(study, f"fast mass-spring {k} it").solve_error for k in (1, 5, 20)]
    assert fms[0] > fms[1] > fms[2] > 0
    assert _run(study, "Chebyshev fast mass-spring 20 it").solve_error < fms[2]
    newton = [_run(study, f"Newton {k} it").solve_error for k in (1, 3)]
    assert newton[1] < 1e-3 * fms[0] and newton[1] < newton[0]
    for r in study["runs"]:
        assert not r.failed and np.isfinite(r.time_per_frame) and r.time_per_frame > 0
        assert len(r.energy) == len(study["times"]) == 9


def test_trajectory_error_is_bounded_below_by_implicit_eulers_own_error(study):
    floor = study["reference"]["trajectory"]["error_vs_implicit_euler"]
    assert floor > 0
    newton3 = _run(study, "Newton 3 it")
    # the converged solve is implicit Euler: its trajectory error is implicit Euler's
    assert newton3.trajectory_error == pytest.approx(floor, rel=1e-2)


def test_bad_method_lists_raise():
    with pytest.raises(UnknownNameError, match="work-precision method family"):
        expand_methods([{"family": "verlet"}])
    with pytest.raises(InputError, match="iterations"):
        expand_methods([{"family": "newton", "iterations": [0]}])
