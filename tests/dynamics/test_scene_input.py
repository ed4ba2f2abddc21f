"""Scene files: bad input exits 2 with one line and no output, declared forces only, lean runs,
optional outputs (xdmf, png, gif), output cadence, velocity expressions, docs cover the schema."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from femkit.case import load_case
from femkit.cli import main
from femkit.case.scene.run import build_system, output_every, run_scene, state_checksum
from femkit.case.scene.schema import SCENE_SCHEMA
from femkit.errors import CaseFileError, UnknownNameError

ROOT = Path(__file__).parents[2]

ROPE = {
    "problem": "mass_spring",
    "system": {"type": "rope", "n": 6, "length": 1.0, "k": 500.0, "total_mass": 0.6},
    "forces": {"gravity": 9.81},
    "integrator": {"method": "velocity_verlet"},
    "dt": 1e-3,
    "t_end": 0.05,
    "output": {"dir": "out"},
}


def write(tmp_path, data, name="scene.yaml"):
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    return p


def changed(fn):
    d = json.loads(json.dumps(ROPE))
    fn(d)
    return d


BAD = {
    "misspelled-top-key": (changed(lambda d: d.update(integrater=d.pop("integrator"))),
                           ["integrater", "did you mean 'integrator'"]),
    "misspelled-system-key": (changed(lambda d: d["system"].update(lenght=1.0)),
                              ["system.lenght", "did you mean 'length'", "valid keys"]),
    "cloth-key-on-rope": (changed(lambda d: d["system"].update(k_structural=1.0)),
                          ["system.k_structural", "unknown key"]),
    "unknown-integrator": (changed(lambda d: d.update(integrator={"method": "rk5"})),
                           ["integrator.method", "rk5", "rk4", "symplectic_euler"]),
    "bad-integrator-option": (changed(lambda d: d.update(
        integrator={"method": "newmark", "options": {"betta": 0.3}})),
        ["integrator.options", "betta"]),
    "unknown-linear-solver": (changed(lambda d: d.update(linear_solver={"method": "gmres"})),
                              ["linear_solver.method", "gmres", "direct", "pcg"]),
    "unknown-preconditioner": (changed(lambda d: d.update(
        linear_solver={"method": "pcg", "preconditioner": "ilu"})),
        ["linear_solver.preconditioner", "ilu", "jacobi"]),
    "unknown-force": (changed(lambda d: d.update(forces=[{"type": "magnetism"}])),
                      ["forces[0].type", "magnetism", "gravity"]),
    "force-key-misspelled": (changed(lambda d: d.update(
        forces=[{"type": "ground", "stifness": 10.0}])),
        ["forces[0].stifness", "did you mean 'stiffness'"]),
    "unknown-system-type": (changed(lambda d: d["system"].update(type="jelly")),
                            ["system.type", "jelly", "cloth"]),
    "unknown-geometry": (changed(lambda d: d.update(system={
        "type": "mesh", "geometry": "circle", "h": 0.2, "k": 10.0})),
        ["system.geometry", "circle", "disk"]),
    "negative-dt": (changed(lambda d: d.update(dt=-0.1)), ["dt"]),
    "unsafe-velocity": (changed(lambda d: d["system"].update(velocity=["__import__('os')", "0"])),
                        ["system.velocity[0]", "not allowed"]),
    "every-and-interval": (changed(lambda d: d["output"].update(every=2, interval=0.01)),
                           ["output", "every", "interval"]),
}


@pytest.mark.parametrize("name", list(BAD))
def test_bad_scene_exits_2_with_one_line_and_no_output(tmp_path, capsys, name):
    data, needles = BAD[name]
    path = write(tmp_path, data)
    assert main(["solve", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("femkit: error: ")
    for needle in needles:
        assert needle in err, (needle, err)
    assert not (tmp_path / "out").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.yaml"]


def test_unknown_integrator_is_an_unknown_name_error(tmp_path):
    with pytest.raises(UnknownNameError) as info:
        load_case(write(tmp_path, ROPE), integrator={"method": "rk5"})
    assert "rk4" in info.value.valid and "fast_mass_spring" in info.value.valid


@pytest.mark.parametrize("forces, kinds", [
    ({}, []),
    ([], []),
    ({"gravity": 9.81}, ["Gravity"]),
    ({"viscous": {"gamma": 0.1}, "ground": {"stiffness": 100.0, "height": -2.0}},
     ["ViscousDamping", "GroundContact"]),
    ([{"type": "sphere", "centre": [0.5, -0.5], "radius": 0.1, "stiffness": 100.0},
      {"type": "sphere", "centre": [0.2, -0.5], "radius": 0.1, "stiffness": 100.0},
      {"type": "rayleigh", "alpha": 0.1}], ["SphereContact", "SphereContact", "RayleighDamping"]),
], ids=["mapping-none", "list-none", "gravity", "viscous+ground", "two-spheres+rayleigh"])
def test_only_declared_forces_are_built(tmp_path, forces, kinds):
    case = load_case(write(tmp_path, changed(lambda d: d.update(forces=forces))))
    system, _ = build_system(case)
    assert sorted(type(f).__name__ for f in system.forces) == sorted(kinds)
    assert not np.any(system.damping)             # no dashpot unless declared
    e = system.energies(system.x0, system.v0)
    if "Gravity" not in kinds:
        assert e["gravity"] == 0.0
        # without gravity the rope at rest stays exactly at rest
        res = run_scene(case, write=False, quiet=True)
        np.testing.assert_array_equal(res.trajectory.x[-1], system.x0)


def test_dashpot_declared_as_force_or_key(tmp_path):
    a, _ = build_system(load_case(write(tmp_path, ROPE), forces=[{"type": "dashpot", "c": 0.5}]))
    b, _ = build_system(load_case(write(tmp_path, ROPE), system={"damping": 0.5}))
    assert np.all(a.damping == 0.5) and np.all(b.damping == 0.5)
    with pytest.raises(CaseFileError, match="not both"):
        load_case(write(tmp_path, ROPE), system={"damping": 0.5},
                  forces=[{"type": "dashpot", "c": 0.5}])


LEAN = """
import sys
from femkit.cli import main
code = main(["solve", sys.argv[1], "-q"])
heavy = sorted(m for m in ("matplotlib", "imageio", "pyamg", "gmsh") if m in sys.modules)
print(code, ",".join(heavy))
"""


def test_scene_without_pictures_imports_no_matplotlib_or_imageio(tmp_path):
    path = write(tmp_path, ROPE)
    proc = subprocess.run([sys.executable, "-c", LEAN, str(path)], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    code, heavy = proc.stdout.split("\n")[0].split(" ", 1) if " " in proc.stdout else (proc.stdout.strip(), "")
    assert code.strip() == "0"
    assert heavy.strip() == ""


def test_png_gif_and_xdmf_on_request(tmp_path, monkeypatch):
    import imageio.v2 as imageio
    import meshio

    path = write(tmp_path, changed(lambda d: d["output"].update(
        png=True, gif=True, xdmf=True, vtu=False, every=10)))
    elsewhere = tmp_path / "cwd"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)             # the .h5 must land next to the .xdmf, not here
    assert main(["solve", str(path), "-q"]) == 0
    assert list(elsewhere.iterdir()) == []
    out = tmp_path / "out"
    files = sorted(p.name for p in out.iterdir())
    assert files == ["animation.gif", "energy.csv", "final.png", "result.json", "scene.h5",
                     "scene.xdmf"]
    assert imageio.imread(out / "final.png").ndim == 3
    gif = imageio.mimread(out / "animation.gif")
    assert len(gif) == 6                       # 50 steps every 10: frames at 0, 10, ..., 50
    with meshio.xdmf.TimeSeriesReader(str(out / "scene.xdmf")) as reader:
        points, cells = reader.read_points_cells()
        assert reader.num_steps == 6
        t, pd, _ = reader.read_data(reader.num_steps - 1)
    assert t == pytest.approx(0.05)
    assert pd["position"].shape == (6, 3) and np.isfinite(pd["position"]).all()
    result = json.loads((out / "result.json").read_text())
    assert result["files"] == ["scene.xdmf", "scene.h5", "energy.csv", "final.png",
                               "animation.gif", "result.json"]


@pytest.mark.parametrize("output, every, frames", [
    ({"every": 7}, 7, 9),              # 50 steps: 0, 7, ..., 49, and the last step 50
    ({"interval": 0.01}, 10, 6),
    ({"frames": 5}, 10, 6),
    ({}, 1, 51),                       # default: about 100 frames, at most one per step
], ids=["every", "interval", "frames", "default"])
def test_output_cadence(tmp_path, output, every, frames):
    case = load_case(write(tmp_path, ROPE), output=output)
    assert output_every(case) == every
    res = run_scene(case, write=False, quiet=True)
    assert len(res.trajectory.times) == frames
    assert res.trajectory.times[-1] == pytest.approx(0.05)


def test_time_expressions_and_velocity_field(tmp_path):
    case = load_case(write(tmp_path, ROPE), dt="1/1000", t_end="5*dt0",
                     constants={"dt0": 0.001},
                     system={"velocity": ["0", "-2*x"]})
    assert case.spec.dt == pytest.approx(1e-3) and case.spec.t_end == pytest.approx(5e-3)
    system, _ = build_system(case)
    expected = np.stack([np.zeros(6), -2 * system.x0[:, 0]], 1)
    expected[0] = 0.0                          # the pinned first node does not move
    np.testing.assert_allclose(system.v0, expected)
    with pytest.raises(CaseFileError, match="needs 2 components"):
        build_system(load_case(write(tmp_path, ROPE), system={"velocity": ["0", "0", "1"]}))


def test_checksum_tracks_the_state(tmp_path):
    case = load_case(write(tmp_path, ROPE))
    a = run_scene(case, write=False, quiet=True).to_dict()["final_state"]["checksum"]
    b = run_scene(load_case(write(tmp_path, ROPE)), write=False, quiet=True).to_dict()
    c = run_scene(load_case(write(tmp_path, ROPE), dt=5e-4), write=False, quiet=True).to_dict()
    assert a == b["final_state"]["checksum"] != c["final_state"]["checksum"]
    x = np.array([[0.1234567891, -2.0]])
    assert state_checksum(x) == state_checksum(x + 1e-12) != state_checksum(x + 1e-6)


def test_summary_is_printed_unless_quiet(tmp_path, capsys):
    path = write(tmp_path, ROPE)
    assert main(["solve", str(path)]) == 0
    text = capsys.readouterr().out
    for needle in ("rope: 6 particles, 5 springs", "velocity_verlet (order 2, explicit, symplectic)",
                   "steps     50 of 50", "energy    drift", "verdict   stable", "critical dt"):
        assert needle in text
    assert main(["solve", str(path), "-q"]) == 0
    assert capsys.readouterr().out == ""


def _property_names(node, out):
    if isinstance(node, dict):
        for k, v in node.get("properties", {}).items():
            out.add(k)
            _property_names(v, out)
        for key, v in node.items():
            if key != "properties":
                _property_names(v, out)
    elif isinstance(node, list):
        for v in node:
            _property_names(v, out)
    return out


def test_docs_cover_every_scene_key():
    doc = (ROOT / "docs" / "scenes.md").read_text()
    names = _property_names(SCENE_SCHEMA, set())
    assert {"k_structural", "energy_growth_limit", "stiffness", "every", "preconditioner"} <= names
    missing = sorted(n for n in names if f"`{n}`" not in doc)
    assert not missing, f"keys missing from docs/scenes.md: {missing}"
    from femkit.case.scene.output import RESULT_KEYS, energy_columns

    missing = [k for k in (*RESULT_KEYS, *energy_columns(3)) if f"`{k}`" not in doc]
    assert not missing, f"output keys missing from docs/scenes.md: {missing}"


def test_schema_and_builder_registries_name_the_same_types():
    from femkit.case.scene.run import FORCES, SYSTEMS
    from femkit.case.scene.schema import FORCE_TYPES, SYSTEM_TYPES

    assert set(FORCES.names()) | {"dashpot"} == set(FORCE_TYPES)  # dashpot: a spring coefficient
    assert set(SYSTEMS.names()) == set(SYSTEM_TYPES)
