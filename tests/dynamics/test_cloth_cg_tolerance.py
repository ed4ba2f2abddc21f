"""Implicit steps accept a linear solve on the true residual only, and with residual replacement
they no longer die at SOFA's CG tolerance (issue 18, part 4).

The bundled hanging cloth (15 x 15, dt = 0.01, 2 s) with implicit Euler and
``linear_solver: {method: cg, rtol: 1e-12}`` raised SolverError at relative residual 1.002e-12
after 115 iterations; it must complete, every recorded step equal to the direct solver's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femkit.case import load_case
from femkit.case.scene.run import build_system
from femkit.dynamics.simulate import simulate
from femkit.dynamics.integrators.base import StepContext
from femkit.solvers import SolverSpec

SCENE = Path(__file__).parents[2] / "cases" / "scenes" / "hanging_cloth.yaml"


def test_hanging_cloth_implicit_euler_with_cg_at_rtol_1e_12_matches_direct():
    case = load_case(SCENE)
    system, _ = build_system(case)
    dt, t_end = case.data["dt"], case.data["t_end"]
    runs = {}
    for name, spec in (("cg", SolverSpec("cg", rtol=1e-12)), ("direct", SolverSpec("direct"))):
        ctx = StepContext(spec)
        runs[name] = simulate(system, "implicit_euler", dt, t_end, ctx=ctx, record_every=1)
        assert runs[name].completed, runs[name].reason
    cg, direct = runs["cg"], runs["direct"]
    assert cg.steps == direct.steps == round(t_end / dt)
    scale = np.max(np.abs(direct.x))
    assert np.max(np.abs(cg.x - direct.x)) <= 1e-8 * scale
    assert np.max(np.abs(cg.v - direct.v)) <= 1e-8 * max(np.max(np.abs(direct.v)), 1.0)
