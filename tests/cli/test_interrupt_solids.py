"""A stop request during a solid run is answered at once, as for the other kinds (issue 30: a
solid dynamics run signalled at 2-5 s exited 0, said ``converged`` and drew its pictures for
seconds more). During the time steps: the frames so far are written, ``result.json`` says
``interrupted: true`` and ``verdict: interrupted``, no pictures, exit 130 / 143. During the
PNG or the GIF: the picture is abandoned at once, the frames (all computed) are kept, marked.

Each test signals a ``femkit solve`` subprocess once it is inside the work under test and
measures signal-to-exit time (target 1 s; 3 s allowed, scaled by the load per core)."""

import json
import signal
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helper
from _signals import signal_inside, signal_when_ready, slack  # noqa: E402

SIGNALS = pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                                  ids=["SIGINT", "SIGTERM"])

#: the bundled vibrating beam, integrated for 20 s (4,000 Newton steps: minutes)
BEAM = {
    "problem": "solid",
    "name": "beam",
    "mesh": {"geometry": "beam", "h": 0.1, "params": {"length": 2.0, "width": 0.2, "height": 0.2}},
    "material": {"model": "stable_neo_hookean", "E": 1.0e8, "nu": 0.3, "density": 1000.0},
    "boundaries": [{"tag": "clamped", "type": "fixed"}],
    "gravity": [0.0, 0.0, -9.81],
    "integrator": "newton",
    "dt": 0.005,
    "t_end": 20.0,
    "output": {"dir": "out", "frames": 400, "png": True, "gif": True},
}

#: a small static case whose pictures are drawn after a quick solve
CUBE = {
    "problem": "solid",
    "name": "cube",
    "mesh": {"geometry": "unit_cube", "h": 0.5},
    "material": {"model": "stable_neo_hookean", "E": 1000.0, "nu": 0.3},
    "boundaries": [{"tag": "xmin", "type": "fixed"},
                   {"tag": "xmax", "type": "traction", "traction": [0.0, 0.0, -20.0]}],
    "static": {"load_steps": 3},
    "output": {"dir": "out"},
}

#: ``python -c SLOW_DRIVER module:attr femkit-args...``: ``attr`` replaced by a spy that says
#: READY and then takes 30 s (a slow render: a large mesh, a loaded machine) before the real
#: call, so the signal surely lands inside that picture.
SLOW_DRIVER = r"""
import importlib, sys, time
target, argv = sys.argv[1], sys.argv[2:]
module, name = target.split(":")
owner = importlib.import_module(module)
real = getattr(owner, name)

def spy(*args, **kwargs):
    print("READY", file=sys.stderr, flush=True)
    time.sleep(30)
    return real(*args, **kwargs)

setattr(owner, name, spy)
from femkit.cli import entry
sys.argv = ["femkit", *argv]
entry()
"""


def _case(tmp_path, data) -> Path:
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _kept(tmp_path) -> tuple[dict, list]:
    """result.json and the frames the pvd lists (each on disk); nothing left beside ``out``."""
    out = tmp_path / "out"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.yaml", "out"]
    result = json.loads((out / "result.json").read_text())
    listed = [d.get("file") for d in ET.parse(out / "solid.pvd").getroot().iter("DataSet")]
    assert listed and all((out / f).is_file() for f in listed)
    assert listed == [f"frames/{p.name}" for p in sorted((out / "frames").iterdir())]
    assert result["frames"] == len(listed)
    return result, sorted(p.name for p in out.iterdir())


@SIGNALS
def test_signal_during_the_time_steps_writes_the_frames_so_far_marked(tmp_path, sig, code):
    (tmp_path / "out").mkdir()   # an earlier complete run there: replaced by the marked one
    (tmp_path / "out" / "result.json").write_text('{"verdict": "converged"}\n')
    # signalled once the first time step is done (its progress update), while the next go on
    rc, elapsed, err = signal_inside("femkit.progress:Progress.update",
                                     ["solve", str(_case(tmp_path, BEAM)), "--quiet"], sig,
                                     cwd=tmp_path)
    assert rc == code, err
    assert elapsed < slack(), elapsed
    assert f"interrupted by {sig.name}" in err and "Traceback" not in err
    result, files = _kept(tmp_path)
    assert result["interrupted"] is True and result["verdict"] == "interrupted"
    assert result["converged"] is False
    assert 0 < result["steps"] < result["steps_planned"] == 4000
    assert result["times"][-1] == pytest.approx(result["steps"] * BEAM["dt"])  # the state at the stop
    assert "deformed.png" not in files and "animation.gif" not in files


@SIGNALS
@pytest.mark.parametrize("picture", ["png", "gif"])
def test_signal_while_drawing_a_picture_abandons_it_and_keeps_the_frames(tmp_path, sig, code,
                                                                          picture):
    data = {**CUBE, "output": {**CUBE["output"], "png": picture == "png", "gif": picture == "gif"}}
    rc, elapsed, err = signal_when_ready(
        SLOW_DRIVER, ["femkit.case.solid.plot:plot_solid_frame", "solve",
                      str(_case(tmp_path, data)), "--quiet"], "READY", sig, cwd=tmp_path)
    assert rc == code, err
    assert elapsed < slack(), elapsed
    assert f"interrupted by {sig.name}" in err and "Traceback" not in err
    result, files = _kept(tmp_path)
    assert result["interrupted"] is True
    assert result["verdict"] == "converged" and result["frames"] == 4   # the solve was complete
    assert "deformed.png" not in files and "animation.gif" not in files
    assert not [f for f in files if f.startswith(".")]                  # no half-written picture
