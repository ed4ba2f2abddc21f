"""Bundled mass-spring scenes through `femkit solve`: exit codes, readable outputs, physics checks.

Each bundled scene in cases/scenes/ runs through femkit.cli.main (reduced in size/time where
the full scene is a benchmark), and its outputs are read back with meshio / csv / json.
"""

import csv
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import yaml

from femkit.cli import main
from femkit.case.scene.output import RESULT_KEYS, energy_columns

ROOT = Path(__file__).parents[2]
SCENES = ROOT / "cases" / "scenes"

#: scene -> (overrides merged into the file, expected exit code)
BUNDLED = {
    "hanging_cloth": ({"system": {"nx": 8, "ny": 8}, "t_end": 0.3}, 0),
    "rope_pendulum": ({"t_end": 0.3}, 0),
    "stiff_spring_explicit": ({}, 1),
    "stiff_spring_implicit": ({}, 0),
    "soft_disk": ({"system": {"h": 0.15}, "t_end": 0.6}, 0),
    "liu_cloth": ({"system": {"nx": 21, "ny": 21}, "t_end": 0.2}, 0),
}


def _merge(base, over):
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            _merge(base[k], v)
        else:
            base[k] = v
    return base


def run_scene_file(tmp_path, name, overrides=None, extra_args=()):
    data = _merge(yaml.safe_load((SCENES / f"{name}.yaml").read_text()), overrides or {})
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    code = main(["solve", str(path), "-o", str(out), "-q", *extra_args])
    return code, out


def read_outputs(out):
    import meshio

    result = json.loads((out / "result.json").read_text())
    pvd = ET.parse(out / "scene.pvd").getroot()
    entries = [(float(d.get("timestep")), d.get("file")) for d in pvd.iter("DataSet")]
    frames = [meshio.read(out / f) for _, f in entries]
    with open(out / "energy.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    return result, entries, frames, rows


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Every bundled scene run once (module scope: the tests below share the runs)."""
    done = {}
    for name, (over, _) in BUNDLED.items():
        code, out = run_scene_file(tmp_path_factory.mktemp(name), name, over)
        done[name] = (code, out)
    return done


@pytest.mark.parametrize("name", list(BUNDLED))
def test_bundled_scene_exit_code_and_outputs(runs, name):
    code, out = runs[name]
    assert code == BUNDLED[name][1]
    result, entries, frames, rows = read_outputs(out)
    assert set(result) == set(RESULT_KEYS)
    assert result["problem"] == "mass_spring"
    # the .pvd lists every frame, in time order, and each file exists and reads back
    assert len(entries) == result["frames"] == len(frames) >= 2
    times = [t for t, _ in entries]
    assert times == sorted(times) and times[0] == 0.0
    dim = result["system"]["dim"]
    for m in frames:
        assert m.points.shape == (result["system"]["particles"], 3)
        assert np.isfinite(m.points).all() and np.isfinite(m.point_data["velocity"]).all()
        assert m.cells_dict["line"].shape == (result["system"]["springs"], 2)
        if result["system"]["triangles"]:
            assert m.cells_dict["triangle"].shape == (result["system"]["triangles"], 3)
    if dim == 2:
        assert all(np.all(m.points[:, 2] == 0.0) for m in frames)
    # energy.csv: the documented columns, one row per frame, finite, same times as the .pvd
    assert rows[0] == energy_columns(dim)
    table = np.array(rows[1:], dtype=float)
    assert table.shape == (len(frames), len(rows[0]))
    assert np.isfinite(table).all()
    np.testing.assert_allclose(table[:, 0], times, rtol=0, atol=1e-12)
    e = dict(zip(rows[0], table.T))
    np.testing.assert_allclose(e["total"], e["kinetic"] + e["spring"] + e["gravity"]
                               + e["contact"], rtol=1e-12, atol=1e-12)
    assert result["final_state"]["checksum"] and len(result["final_state"]["checksum"]) == 64


def test_stiff_spring_explicit_fails_cleanly(runs):
    """k = 1e6, m = 1, dt = 1/60 with symplectic Euler: h*omega = 16.7 > 2."""
    code, out = runs["stiff_spring_explicit"]
    assert code == 1
    result, entries, frames, _ = read_outputs(out)
    st = result["stability"]
    assert st["verdict"] == "unstable" and result["converged"] is False
    # omega = sqrt(k/m) = 1000, symplectic Euler's bound is 2: dt_crit = 2e-3
    assert st["omega_max"] == pytest.approx(1000.0, rel=1e-6)
    assert st["dt_crit"] == pytest.approx(2e-3, rel=1e-6)
    assert st["h_omega_max"] == pytest.approx(1000.0 / 60.0, rel=1e-6)
    assert st["step"] >= 1 and st["time"] == pytest.approx(st["step"] / 60.0)
    assert st["energy_ratio"] > st["energy_growth_limit"]
    assert st["method"] == "symplectic_euler" and st["reason"]
    # frames stop at the last good step; nothing non-finite was written
    assert result["steps"] == st["step"] - 1 < result["steps_planned"] == 60
    assert entries[-1][0] == pytest.approx(result["steps"] / 60.0)
    assert all(np.isfinite(m.points).all() for m in frames)
    assert result["warnings"] and "critical step" in result["warnings"][0]


def test_stiff_spring_implicit_stays_bounded(runs):
    code, out = runs["stiff_spring_implicit"]
    assert code == 0
    result, _, frames, rows = read_outputs(out)
    assert result["stability"]["verdict"] == "stable" and result["steps"] == 60
    e = np.array(rows[1:], dtype=float)[:, rows[0].index("total")]
    # implicit Euler only removes energy (up to round-off)
    assert np.all(e <= e[0] + 1e-9 * abs(e[0]))
    # and settles at the static equilibrium y = 1 - m g / k = 1 - 1e-5
    assert frames[-1].points[1, 1] == pytest.approx(1.0 - 1e-5, abs=1e-7)
    assert result["linear_solver"]["linear_solves"] == 60


def test_rope_pendulum_conserves_energy_and_keeps_pin(runs):
    _, out = runs["rope_pendulum"]
    result, _, frames, _ = read_outputs(out)
    assert result["integrator"]["symplectic"] is True
    assert abs(result["energy"]["drift"]) < 1e-2
    for m in frames:
        np.testing.assert_array_equal(m.points[0], [0.0, 0.0, 0.0])
    # the free end falls under gravity
    assert frames[-1].points[-1, 1] < -0.05


def test_soft_disk_lands_on_the_ground(runs):
    _, out = runs["soft_disk"]
    result, entries, frames, _ = read_outputs(out)
    assert result["system"]["forces"] == ["gravity", "ground", "dashpot"]
    low = [float(m.points[:, 1].min()) for m in frames]
    assert low[0] == pytest.approx(0.3, abs=1e-9)      # radius 0.3 disk centred at y = 0.6
    # free fall to the ground takes sqrt(2 * 0.3 / 9.81) = 0.247 s; then the ground holds it
    t_hit = math.sqrt(2 * 0.3 / 9.81)
    before = [lo for (t, _), lo in zip(entries, low) if t < t_hit - 0.02]
    assert all(lo > 0.0 for lo in before)
    assert min(low) < 0.01                               # it did reach the ground
    assert min(low) > -0.05                              # penalty contact: shallow penetration


def test_cloths_keep_pins_and_fall(runs):
    for name in ("hanging_cloth", "liu_cloth"):
        _, out = runs[name]
        result, _, frames, _ = read_outputs(out)
        pinned = frames[0].point_data["pinned"].astype(bool)
        assert pinned.sum() == result["system"]["pinned"] == 2
        for m in frames:
            np.testing.assert_array_equal(m.points[pinned], frames[0].points[pinned])
        assert frames[-1].points[~pinned, 2].mean() < -0.01   # gravity along -z
    liu = json.loads((runs["liu_cloth"][1] / "result.json").read_text())
    # the (M + h^2 L) factorisation is built once and reused for every step; the scene selects
    # SuperLU through its linear_solver spec (the cholesky fast path is the optional extra)
    assert liu["linear_solver"]["factorizations"] == 1
    assert liu["linear_solver"]["method"] == "direct"
    assert liu["integrator"]["options"] == {"iterations": 10, "tol": None, "chebyshev": False,
                                            "chebyshev_rho": None, "chebyshev_delay": 2,
                                            "chebyshev_warmup": 10}
