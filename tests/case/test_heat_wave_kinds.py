"""``problem: heat`` and ``problem: wave`` through femkit solve: outputs read back by meshio,
a manufactured solution with time-dependent Dirichlet and Neumann data reproduced to round-off,
the error history, the bad inputs of issue 33 refused in one line with nothing written, and the
kinds in ``femkit list``, the schema and ``--dry-run``.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from femkit.case import load_case
from femkit.cli import main

ROOT = Path(__file__).resolve().parents[2]

#: u = t^2 (x + y) + x: linear in space, quadratic in time. P1 holds it exactly, the load
#: f = rho_c u_t = 2 rho_c t (x + y) is integrated exactly by gauss3, and the trapezoidal rule
#: (Crank-Nicolson) and BDF2 are exact for a quadratic in time: the discrete solution is the
#: exact one up to round-off. Dirichlet data on three sides change in time, the right side
#: carries the time-dependent flux kappa du/dx = kappa (t^2 + 1).
MANUFACTURED = {
    "problem": "heat", "name": "mms",
    "mesh": {"geometry": "unit_square", "h": 0.2},
    "coefficient": 2.0, "rho_c": 3.0,
    "source": "2*3*t*(x + y)",
    "initial": "x",
    "boundary": {"dirichlet": [{"tags": ["left", "bottom", "top"], "value": "t**2*(x + y) + x"}],
                 "neumann": [{"tags": ["right"], "flux": "2*(t**2 + 1)"}]},
    "exact": {"u": "t**2*(x + y) + x", "grad": ["t**2 + 1", "t**2"]},
    "quadrature": {"load": "gauss3"},
    "integrator": "crank_nicolson", "dt": 0.05, "t_end": 0.5,
    "output": {"dir": "out"},
}


def _write(tmp_path: Path, data: dict, name: str = "case.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("integrator", ["crank_nicolson", "bdf2"])
def test_manufactured_solution_with_time_dependent_boundary_data_is_exact(tmp_path, integrator):
    case = load_case(_write(tmp_path, {**MANUFACTURED, "integrator": integrator}))
    r = case.run(write=False, quiet=True)
    assert r.converged and r.march.steps == 10
    assert r.errors["max_over_time"]["max_nodal"] < 1e-10
    assert r.errors["max_over_time"]["L2"] < 1e-10


def test_implicit_euler_on_the_manufactured_solution_is_first_order(tmp_path):
    errs = []
    for dt in (0.05, 0.025):
        case = load_case(_write(tmp_path, {**MANUFACTURED, "integrator": "implicit_euler", "dt": dt}))
        errs.append(case.run(write=False, quiet=True).errors["final"]["max_nodal"])
    assert errs[0] > 1e-4 and 1.8 < errs[0] / errs[1] < 2.2, errs


def test_heat_solve_writes_a_pvd_series_meshio_reads(tmp_path, capsys):
    meshio = pytest.importorskip("meshio")
    path = _write(tmp_path, {**MANUFACTURED, "output": {"dir": "out", "frames": 5, "gif": True}})
    assert main(["solve", str(path)]) == 0, capsys.readouterr().err
    out = tmp_path / "out"
    data = json.loads((out / "result.json").read_text())
    assert data["problem"] == "heat" and data["converged"] and data["steps"] == 10
    assert data["frames"] == 6 and len(data["errors"]["history"]) == 6
    assert data["linear_solver"]["factorizations"] == 1  # one kept factor for every step
    assert (out / "final.png").stat().st_size > 1000
    from PIL import Image

    with Image.open(out / "animation.gif") as gif:
        assert gif.n_frames == 6
    pvd = (out / "heat.pvd").read_text()
    files = [line.split('file="')[1].split('"')[0] for line in pvd.splitlines() if "file=" in line]
    assert len(files) == 6
    last = meshio.read(out / files[-1])
    x, y = last.points[:, 0], last.points[:, 1]
    np.testing.assert_allclose(last.point_data["u"], 0.25 * (x + y) + x, atol=1e-10)


def test_wave_result_reports_the_energy_per_frame_and_its_drift(tmp_path):
    data = {"problem": "wave", "name": "w", "mesh": {"geometry": "unit_square", "h": 0.2},
            "initial": "sin(pi*x)*sin(pi*y)", "initial_velocity": "x*(1-x)*y*(1-y)",
            "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
            "integrator": "newmark", "dt": 0.01, "t_end": 1.0, "output": {"dir": "out", "frames": 10}}
    r = load_case(_write(tmp_path, data)).run(write=False, quiet=True)
    facts = r.to_dict()
    assert len(facts["energies"]) == 11 and facts["energy_drift"] < 1e-12
    assert facts["energies"][0]["kinetic"] > 0 and facts["energies"][0]["potential"] > 0


def test_a_3d_heat_case_converges_in_space(tmp_path):
    """exp(-3 pi^2 t) sin(pi x) sin(pi y) sin(pi z) on the unit cube: halving h divides the L2
    error by about 4."""
    errs = []
    for h in (0.25, 0.125):
        data = {"problem": "heat", "name": "cube", "mesh": {"geometry": "kuhn_cube", "h": h},
                "initial": "sin(pi*x)*sin(pi*y)*sin(pi*z)",
                "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
                "exact": {"u": "exp(-3*pi**2*t)*sin(pi*x)*sin(pi*y)*sin(pi*z)"},
                "integrator": "bdf2", "dt": 0.0025, "t_end": 0.025, "output": {"dir": "out"}}
        errs.append(load_case(_write(tmp_path, data)).run(write=False, quiet=True)
                    .errors["final"]["L2"])
    assert 3.0 < errs[0] / errs[1] < 5.0, errs


def _refused(tmp_path, capsys, data, *words):
    path = _write(tmp_path, data)
    before = sorted(p.name for p in tmp_path.iterdir())
    start = time.perf_counter()
    code = main(["solve", str(path)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, (w, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written
    assert time.perf_counter() - start < 5.0
    return err


def test_negative_rho_c_is_refused(tmp_path, capsys):
    _refused(tmp_path, capsys, {**MANUFACTURED, "rho_c": -1.0}, "rho_c")


def test_an_unknown_element_is_refused(tmp_path, capsys):
    _refused(tmp_path, capsys, {**MANUFACTURED, "element": "P3"}, "element", "P1, P2")
    _refused(tmp_path, capsys, {**MANUFACTURED, "element": "P2"}, "gauss3", "not exact for P2")


def test_t_end_below_zero_is_refused(tmp_path, capsys):
    _refused(tmp_path, capsys, {**MANUFACTURED, "t_end": -0.5}, "t_end", "positive")


def test_a_time_dependent_value_not_finite_at_some_t_is_refused(tmp_path, capsys):
    bad = {**MANUFACTURED, "boundary": {"dirichlet": [{"tags": ["boundary"],
                                                       "value": "1/(t - 0.25)"}]}}
    _refused(tmp_path, capsys, bad, "boundary.dirichlet[0].value", "non-finite", "t=0.25")


def test_dt_above_the_critical_step_of_explicit_euler_is_refused_naming_the_largest(tmp_path, capsys):
    data = {**MANUFACTURED, "integrator": "explicit_euler", "mass": "lumped", "dt": 0.05}
    err = _refused(tmp_path, capsys, data, "dt", "critical step", "largest stable dt")
    largest = float(err.split("largest stable dt is ")[1].split()[0])
    ok = load_case(_write(tmp_path, {**data, "dt": largest, "t_end": 50 * largest}))
    r = ok.run(write=False, quiet=True)  # at the named step the run is stable
    assert r.converged and r.stability["dt_critical"] >= largest


def test_the_kinds_are_listed_schema_checked_and_planned(tmp_path, capsys):
    assert main(["list", "problems"]) == 0
    out = capsys.readouterr().out
    assert "heat " in out and "wave " in out
    _refused(tmp_path, capsys, {**MANUFACTURED, "rhoc": 1.0}, "rhoc", "rho_c")
    _refused(tmp_path, capsys, {**MANUFACTURED, "integrator": "rk4"}, "rk4", "bdf2", "crank_nicolson")
    path = _write(tmp_path, MANUFACTURED)
    assert main(["solve", str(path), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "steps" in out and "crank_nicolson" in out and not (tmp_path / "out").exists()


def test_the_plan_prices_a_step_by_the_kept_factors_fill_not_by_a_factorisation(tmp_path):
    """Plan structure (no timing): a kept-factor step costs one substitution pair priced from
    the factor's fill (``nnz(L + U) ~ n^1.21``) plus one SpMV, whatever the factorisation costs
    (``~ n^2.9``): the step's share of the factorisation falls with the size, doubling the
    steps doubles the steps stage alone; above the size rule's limit the plan prices the
    iterative step solver the run will use, not a factorisation."""
    from femkit.cost import load_constants
    from femkit.case.transient.setup import SUBSTITUTION_PER_FILL, plan_transient

    c = load_constants()
    share = []
    for h in (0.05, 0.005):
        plans = []
        for t_end in (0.5, 1.0):
            data = {**MANUFACTURED, "mesh": {"geometry": "unit_square", "h": h}, "t_end": t_end,
                    "solver": {"method": "direct"}}
            plans.append(plan_transient(load_case(_write(tmp_path, data)), measure=False))
        st = [{s.name: s.seconds for s in p.stages} for p in plans]
        n, nnz = plans[0].sizes["unknowns"], plans[0].sizes["nonzeros"]
        fill = c["fill"]["direct_coefficient"] * n ** c["fill"]["direct_exponent"]
        per_step = st[0]["steps"] / plans[0].sizes["steps"]
        assert per_step == pytest.approx(SUBSTITUTION_PER_FILL * fill
                                         + c["seconds"]["iteration_per_nonzero"]["cg"] * nnz)
        assert st[1]["steps"] == pytest.approx(2 * st[0]["steps"])
        assert st[1]["factor"] == st[0]["factor"] > 0
        share.append(per_step / st[0]["factor"])
    assert share[1] < share[0] / 10   # 100x the unknowns: a step is no fixed share of a factor
    big = {**MANUFACTURED, "mesh": {"geometry": "unit_square", "h": 0.002}}   # ~290k unknowns
    plan = plan_transient(load_case(_write(tmp_path, big)), measure=False)
    factor = next(s for s in plan.stages if s.name == "factor")
    assert "preconditioner kept" in factor.detail and "pcg" in factor.detail


@pytest.mark.parametrize("name", sorted(p.name for p in (ROOT / "cases").glob("*.yaml")
                                        if p.name.startswith(("heat_", "wave_"))))
def test_bundled_heat_and_wave_cases_run(name, tmp_path):
    r = load_case(ROOT / "cases" / name).run(write=False, quiet=True)
    assert r.converged
    if r.errors is not None:
        assert r.errors["max_over_time"]["L2"] < 5e-3


def test_every_key_of_both_schemas_is_documented():
    """Top-level and ``output`` keys (the shared fragments, mesh, solver and limits, are
    documented with the Poisson files in docs/case-files.md)."""
    from femkit.case.heat.schema import heat_schema
    from femkit.case.wave.schema import wave_schema

    keys = set()
    for schema in (heat_schema(), wave_schema()):
        keys |= set(schema["properties"]) | set(schema["properties"]["output"]["properties"])
    doc = (ROOT / "docs" / "heat_wave.md").read_text()
    missing = sorted(k for k in keys if f"`{k}`" not in doc)
    assert not missing, f"keys missing from docs/heat_wave.md: {missing}"


#: u = t^2 (x + y) / 2 + x + t y: constant acceleration x + y (the source, rho = 2), linear in
#: space, so Newmark's average acceleration and central difference are exact (the midpoint rule
#: is not: it takes the load at t + dt/2 but K u as the average of the end points, and here
#: F(t) - K u(t) is constant while F and K u are quadratic in t);
#: Dirichlet data move in time on three sides, the right side carries kappa du/dx = 3 (t^2/2 + 1).
WAVE_MMS = {
    "problem": "wave", "name": "wave_mms", "mesh": {"geometry": "unit_square", "h": 0.25},
    "coefficient": 3.0, "rho": 2.0, "source": "2*(x + y)",
    "initial": "x", "initial_velocity": "y",
    "boundary": {"dirichlet": [{"tags": ["left", "bottom", "top"],
                                "value": "t**2*(x + y)/2 + x + t*y"}],
                 "neumann": [{"tags": ["right"], "flux": "3*(t**2/2 + 1)"}]},
    "exact": {"u": "t**2*(x + y)/2 + x + t*y", "grad": ["t**2/2 + 1", "t**2/2 + t"]},
    "quadrature": {"load": "gauss3"}, "dt": 0.02, "t_end": 0.4, "output": {"dir": "out"},
}


@pytest.mark.parametrize("integrator", ["newmark", "central_difference"])
def test_wave_manufactured_solution_with_moving_boundary_data_is_exact(tmp_path, integrator):
    case = load_case(_write(tmp_path, {**WAVE_MMS, "integrator": integrator}))
    r = case.run(write=False, quiet=True)
    assert r.converged and r.errors["max_over_time"]["max_nodal"] < 1e-10, r.errors["max_over_time"]


def test_adaptive_steps_through_the_heat_kind(tmp_path, capsys):
    data = {**MANUFACTURED, "integrator": "implicit_euler", "rtol_t": 1e-3, "dt": 0.001}
    r = load_case(_write(tmp_path, data)).run(write=False, quiet=True)
    ad = r.to_dict()["adaptive"]
    assert r.converged and r.march.t_reached == pytest.approx(0.5)
    assert ad["accepted"] == len(ad["steps"]) > 5 and len({s["dt"] for s in ad["steps"]}) > 2
    assert all(s["error_estimate"] <= 1.0 for s in ad["steps"])
    for name in ("crank_nicolson", "bdf2"):   # Milne's device (femkit.dynamics.mol.estimate)
        r2 = load_case(_write(tmp_path, {**data, "integrator": name})).run(write=False, quiet=True)
        steps = r2.to_dict()["adaptive"]["steps"]
        assert r2.converged and r2.march.t_reached == pytest.approx(0.5)
        assert all(s["error_estimate"] <= 1.0 for s in steps) and len(steps) < ad["accepted"]
    _refused(tmp_path, capsys, {**data, "integrator": "explicit_euler"}, "rtol_t",
             "bdf2, crank_nicolson, implicit_euler")
    _refused(tmp_path, capsys, {**data, "integrator": {"method": "crank_nicolson",
                                                       "options": {"theta": 0.75}}},
             "rtol_t", "bdf2, crank_nicolson, implicit_euler")


def test_p2_heat_converges_at_order_three_and_writes_quadratic_frames(tmp_path):
    """``element: P2`` (femkit.elements): the L2 error at t_end falls by ~8 per halving of h
    (BDF2 with a small dt, so the time error is far below), against ~4 for P1; the frames are
    VTK quadratic triangles meshio reads, one value per P2 dof."""
    meshio = pytest.importorskip("meshio")
    errs = {}
    for el in ("P1", "P2"):
        for h in (0.25, 0.125):
            data = {"problem": "heat", "mesh": {"geometry": "unit_square", "h": h}, "element": el,
                    "initial": "sin(pi*x)*sin(pi*y)",
                    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
                    "exact": {"u": "exp(-2*pi**2*t)*sin(pi*x)*sin(pi*y)"},
                    "integrator": "bdf2", "dt": 0.0005, "t_end": 0.05,
                    "output": {"dir": f"out_{el}_{h}", "frames": 1, "png": False}}
            r = load_case(_write(tmp_path, data)).run(write=el == "P2" and h == 0.125, quiet=True)
            errs[el, h] = r.errors["final"]["L2"]
    assert 3.0 < errs["P1", 0.25] / errs["P1", 0.125] < 5.0, errs
    assert 6.5 < errs["P2", 0.25] / errs["P2", 0.125] < 10.0, errs
    frame = meshio.read(tmp_path / "out_P2_0.125" / "frames" / "frame_00001.vtu")
    assert frame.cells[0].type == "triangle6"
    assert frame.point_data["u"].shape == (len(frame.points),)


def test_default_step_solver_follows_the_size_rule_and_a_named_one_is_kept(tmp_path, monkeypatch):
    """Without a named method the steps factorise up to DIRECT_LIMIT unknowns and above it use
    PCG with one kept AMG hierarchy (here the limit lowered to 0 so a small mesh crosses it);
    the manufactured solution stays exact to round-off either way."""
    from femkit.dynamics.mol import system as mol_system

    small = load_case(_write(tmp_path, MANUFACTURED)).run(write=False, quiet=True)
    assert small.linear["method"] == "direct" and small.linear["factorizations"] == 1
    monkeypatch.setitem(mol_system.DIRECT_LIMIT, 2, 0)
    large = load_case(_write(tmp_path, MANUFACTURED)).run(write=False, quiet=True)
    lin = large.linear   # stiffness ratio ~ 8 dt kappa / (rho_c h^2) ~ 7: IC(0)
    assert (lin["method"], lin["preconditioner"]) == ("pcg", "ic0")
    assert lin["factorizations"] == 0 and lin["preconditioner_setups"] == 1   # one matrix
    assert large.errors["max_over_time"]["max_nodal"] < 1e-9
    monkeypatch.setattr(mol_system, "IC0_LIMIT", 0.1)   # as if dt were far larger: AMG
    stiff = load_case(_write(tmp_path, MANUFACTURED)).run(write=False, quiet=True)
    assert stiff.linear["preconditioner"] == "amg_rs"
    assert stiff.errors["max_over_time"]["max_nodal"] < 1e-9
    named = load_case(_write(tmp_path, {**MANUFACTURED, "solver": {"method": "direct"}}))
    assert named.run(write=False, quiet=True).linear["method"] == "direct"


def test_a_forced_unstable_run_reports_no_norm_for_overflowing_frames(tmp_path):
    """Explicit Euler forced far above its critical step grows by ~5x a step: frames past
    1e100 get no error norm (their squares overflow) instead of stopping the run."""
    data = {**MANUFACTURED, "integrator": "explicit_euler", "dt": 0.05, "t_end": 5.0,
            "output": {"dir": "out", "frames": 50}}
    r = load_case(_write(tmp_path, data)).with_options(force=True).run(write=False, quiet=True)
    hist = r.errors["history"]
    assert hist[0]["L2"] is not None and hist[0]["L2"] < 1e-12
    assert any(h["L2"] is None for h in hist)
    assert all(h["L2"] is None or h["L2"] < 1e100 for h in hist)
