"""One Ctrl-C (or SIGTERM) while a scene writes its frames is answered within a second: the
frames written so far are kept and listed, result.json says interrupted, exit 130 / 143.

The frames are written by a writer thread while the simulation runs, so the signal lands while
both go on: the simulation stops after its step, the writer finishes the frames it was handed
(every recorded frame is on disk, readable) and the pvd lists exactly those."""

import json
import signal
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helper
from _signals import signal_inside, slack  # noqa: E402

SCENE = {
    "problem": "mass_spring",
    "system": {"type": "rope", "n": 400, "length": 1.0, "k": 500.0, "total_mass": 0.6},
    "forces": {"gravity": 9.81},
    "integrator": {"method": "symplectic_euler"},
    "dt": 1e-4,
    "t_end": 0.3,                       # 3000 steps, every one a frame: seconds of writing
    "stability": {"check": False},
    "output": {"dir": "out", "every": 1, "png": True},
}


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                         ids=["SIGINT", "SIGTERM"])
def test_signal_while_writing_frames_keeps_a_consistent_marked_output(tmp_path, sig, code):
    case = tmp_path / "scene.yaml"
    case.write_text(yaml.safe_dump(SCENE))
    # signalled once the first frame is being written (by the writer thread)
    returncode, elapsed, err = signal_inside("femkit.mesh.vtk:VtuFrames.write",
                                             ["solve", str(case), "--quiet"], sig, cwd=tmp_path)
    assert returncode == code, err
    assert elapsed < slack(), elapsed  # target 1 s; 3 s idle, scaled by the load
    assert f"interrupted by {sig.name}" in err and "Traceback" not in err
    out = tmp_path / "out"
    result = json.loads((out / "result.json").read_text())
    assert result["interrupted"] is True
    frames = sorted(p.name for p in (out / "frames").iterdir())
    listed = [d.get("file") for d in ET.parse(out / "scene.pvd").getroot().iter("DataSet")]
    assert 0 < len(frames) == len(listed) == result["frames"] <= result["steps"] + 1
    assert listed == [f"frames/{name}" for name in frames]
    assert result["steps"] < result["steps_planned"]    # stopped while frames were written
    times = [float(d.get("timestep")) for d in ET.parse(out / "scene.pvd").getroot().iter("DataSet")]
    assert times[-1] == pytest.approx(result["t_reached"])   # the state at the stop is the last
    last = meshio.read(out / "frames" / frames[-1])             # every kept frame is whole
    assert last.points.shape == (SCENE["system"]["n"], 3) and np.isfinite(last.points).all()
    assert "final.png" not in {p.name for p in out.iterdir()}  # no plotting after a stop
