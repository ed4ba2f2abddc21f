"""``femkit solve`` end to end: result.json's ``wall`` parts sum to the process's wall time, the
terminal names them, and ``output.compression`` reaches solution.vtu."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from femkit.mesh.vtk import vtu_header

import pytest
import yaml

CASE = {
    "problem": "poisson",
    "mesh": {"geometry": "unit_square", "h": 0.2},
    "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
    "exact": {"u": "sin(pi*x)*sin(pi*y)"},
    "solver": {"method": "pcg", "preconditioner": "jacobi", "rtol": 1e-10},
    "output": {"dir": "out"},
}


def _solve(tmp_path, **output):
    case = dict(CASE, output={"dir": "out", **output})
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(case))
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "femkit.cli", "solve", str(path)], cwd=tmp_path,
                          capture_output=True, text=True, env=dict(os.environ), timeout=300)
    wall = time.perf_counter() - t0
    assert proc.returncode == 0, proc.stderr
    return proc.stdout, json.loads((tmp_path / "out" / "result.json").read_text()), wall


def test_wall_parts_sum_to_the_process_wall_time(tmp_path):
    out, res, measured = _solve(tmp_path)
    w = res["wall"]
    assert w["total"] == pytest.approx(w["startup"] + w["stages"] + w["other"], rel=1e-9)
    assert w["stages"] == pytest.approx(sum(res["timings"].values()), rel=1e-9)
    assert w["startup"] > 0  # the interpreter and the imports are not free
    # the parent's clock brackets the child's: start-up of the parent's subprocess call and the
    # interpreter's exit are the only time outside ``total``
    assert 0 < w["total"] <= measured
    line = next(ln for ln in out.splitlines() if ln.startswith("wall"))
    assert "start-up and imports" in line and "stages" in line


@pytest.mark.parametrize("compression, compressor", [("none", None), ("zlib", "vtkZLibDataCompressor")],
                         ids=["none", "zlib"])
def test_output_compression_reaches_the_vtu(tmp_path, compression, compressor):
    _, res, _ = _solve(tmp_path, compression=compression)
    root = vtu_header(tmp_path / "out" / "solution.vtu")
    assert root.attrib.get("compressor") == compressor
