"""Scene frames written by a writer thread while the run goes on (issue 19): the same bytes as
the synchronous writer, the same data as meshio's own VTU writer, errors of the thread raised
in the run as femkit errors with nothing half-written."""

import json
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import meshio
import numpy as np
import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared case
from _cloth import CLOTH  # noqa: E402

from femkit.case import case_from_dict
from femkit.case.scene.output import FrameStream, write_frames_vtu
from femkit.case.scene.run import build_system
from femkit.errors import FemkitError, MeshError
from femkit.io.background import BackgroundWriter
from femkit.mesh.vtk import VtuFrames, write_cells

def _cloth_case(tmp_path, **over):
    return case_from_dict({**CLOTH, **over}, base_dir=tmp_path)


def _frames(directory: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted((directory / "frames").iterdir())}


def test_thread_frames_are_byte_identical_to_the_synchronous_writer(tmp_path):
    result = _cloth_case(tmp_path).run(quiet=True)            # frames by the writer thread
    threaded = _frames(tmp_path / "out")
    names = write_frames_vtu(tmp_path / "sync", result.system, result.trajectory,
                             result.triangles)
    synchronous = _frames(tmp_path / "sync")
    assert len(threaded) == len(result.trajectory.times) == len(names) == 11
    assert threaded == synchronous


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_compiled_stretch_has_the_numpy_expressions_bits(dim):
    """Large scenes' frames take the stretch from one compiled pass without the GIL: the same
    bits as the NumPy expression small scenes use (frames identical whichever path runs), on
    states from 1e-8 to 1 in size."""
    from femkit.case.scene.output import _stretch
    from femkit.dynamics.kernels.spring_kernels import spring_stretch

    rng = np.random.default_rng(19)
    n, m = 400, 3000
    i, j = rng.integers(0, n, m), rng.integers(0, n, m)
    j[i == j] = (j[i == j] + 1) % n
    rest = rng.uniform(0.1, 2.0, m)
    for scale in (1e-8, 1e-4, 1.0):
        x = rng.normal(scale=scale, size=(n, dim))
        compiled = spring_stretch(x, i, j, rest, np.empty(m))
        dx = np.take(x, j, axis=0) - np.take(x, i, axis=0)
        np.testing.assert_array_equal(compiled, np.sqrt(np.einsum("sd,sd->s", dx, dx)) / rest - 1.0)
        np.testing.assert_array_equal(_stretch(x, i, j, rest), compiled)   # m < threshold: NumPy


def test_frames_hold_the_trajectory_as_meshio_reads_them(tmp_path):
    """Raw appended VTU read back by meshio: points, cells, velocity, pinned and stretch equal
    what meshio's own writer (femkit.mesh.vtk.write_cells) stores for the same frame."""
    result = _cloth_case(tmp_path).run(quiet=True)
    traj, system, tri = result.trajectory, result.system, result.triangles
    k = len(traj.times) - 1
    ours = meshio.read(tmp_path / "out" / "frames" / f"frame_{k:05d}.vtu")
    x, v = traj.x[k], traj.v[k]
    i, j = system.springs[:, 0], system.springs[:, 1]
    stretch = np.linalg.norm(x[j] - x[i], axis=1) / system.rest - 1.0
    write_cells(tmp_path / "meshio.vtu", x, [("line", system.springs), ("triangle", tri)],
                cell_data={"stretch": [stretch, np.zeros(len(tri))]},
                point_data={"velocity": v, "pinned": system.pinned.astype(np.int32)})
    theirs = meshio.read(tmp_path / "meshio.vtu")
    np.testing.assert_array_equal(ours.points, theirs.points)
    assert [c.type for c in ours.cells] == [c.type for c in theirs.cells] == ["line", "triangle"]
    for a, b in zip(ours.cells, theirs.cells):
        np.testing.assert_array_equal(a.data, b.data)
    for name in ("velocity", "pinned"):
        np.testing.assert_array_equal(ours.point_data[name], theirs.point_data[name])
    for a, b in zip(ours.cell_data["stretch"], theirs.cell_data["stretch"]):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-15)


def test_frame_arrays_of_the_wrong_length_are_refused(tmp_path):
    frames = VtuFrames([("line", np.array([[0, 1], [1, 2]]))])
    with pytest.raises(MeshError, match="point_data 'v' has 2 rows"):
        frames.write(tmp_path / "f.vtu", np.zeros((3, 2)), point_data={"v": np.zeros(2)})
    with pytest.raises(MeshError, match="cell type 'polygon' not supported"):
        VtuFrames([("polygon", np.array([[0, 1, 2, 3]]))])


def test_writer_keeps_order_and_relays_errors_as_femkit_errors():
    out = []
    with BackgroundWriter(depth=2) as w:
        for k in range(50):
            w.submit(out.append, k)
        assert w.close() == 50
    assert out == list(range(50))

    def fail(k):
        if k == 3:
            raise OSError(28, "No space left on device")
        out.append(k)

    out.clear()
    w = BackgroundWriter(depth=2)
    with pytest.raises(FemkitError, match="No space left on device"):
        with w:
            for k in range(100):
                w.submit(fail, k)
                time.sleep(0.001)
    assert out == [0, 1, 2]                     # nothing after the failing job
    assert not any(t.name == "femkit writer" for t in threading.enumerate())

    def gone():
        raise MeshError("cannot write frame f.vtu: gone")

    w = BackgroundWriter(depth=1)
    w.submit(gone)
    with pytest.raises(MeshError, match="gone"):  # a femkit error comes through unchanged
        w.close()


def test_writer_close_with_a_stop_keeps_what_was_written():
    out = []
    stop = threading.Event()

    def slow(k):
        time.sleep(0.02)
        out.append(k)
        if k == 2:
            stop.set()

    w = BackgroundWriter(depth=50)
    for k in range(50):
        w.submit(slow, k)
    done = w.close(stop.is_set)
    assert done == len(out) and 3 <= done < 50 and out == list(range(done))


def test_frame_stream_error_leaves_nothing_half_written(tmp_path):
    """An exception in the run while frames are being written: the stream is cancelled and the
    atomic output directory removed; an earlier run at the same place stays as it was."""
    case = _cloth_case(tmp_path)
    case.run(quiet=True)
    before = (tmp_path / "out" / "result.json").read_bytes()
    system, tri = build_system(case)

    def boom(*args, **kwargs):
        raise RuntimeError("simulated failure in the run")

    from femkit.io.atomic import EARLIER_RUN, atomic_directory

    with pytest.raises(RuntimeError):
        with atomic_directory(tmp_path / "out", EARLIER_RUN) as tmp, \
                FrameStream(tmp, system, tri) as frames:
            for k in range(5):
                frames.add(k, 0.1 * k, system.x0.copy(), system.v0.copy())
            boom()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert (tmp_path / "out" / "result.json").read_bytes() == before


#: femkit solve with the frame writer's file removed from under it at its 3rd frame
REMOVE_DRIVER = r"""
import shutil, sys
from femkit.mesh.vtk import VtuFrames
real = VtuFrames.write
calls = []

def write(self, path, *args, **kwargs):
    calls.append(path)
    if len(calls) == 3:
        shutil.rmtree(path.parent)          # the frames directory vanishes mid-run
    return real(self, path, *args, **kwargs)

VtuFrames.write = write
from femkit.cli import entry
sys.argv = ["femkit", *sys.argv[1:]]
entry()
"""


def test_output_removed_mid_run_is_one_line_and_leaves_nothing(tmp_path):
    case = tmp_path / "scene.yaml"
    case.write_text(yaml.safe_dump(CLOTH))
    first = subprocess.run([sys.executable, "-m", "femkit.cli", "solve", str(case), "--quiet"],
                           cwd=tmp_path, capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    before = (tmp_path / "out" / "result.json").read_text()
    p = subprocess.run([sys.executable, "-c", REMOVE_DRIVER, "solve", str(case), "--quiet"],
                       cwd=tmp_path, capture_output=True, text=True)
    assert p.returncode in (1, 2), p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in p.stderr, p.stderr
    assert lines[0].startswith("femkit: error: cannot write frame") and "frame_00002.vtu" in lines[0]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["out", "scene.yaml"]  # no *.tmp-*
    assert (tmp_path / "out" / "result.json").read_text() == before
    assert json.loads(before)["frames"] == 11


def test_simulate_hands_every_recorded_frame_to_on_record():
    """``on_record(k, t, x, v)`` sees exactly the recorded frames, in order, as kept copies (an
    unstable run included: its last good state is the last frame)."""
    from femkit.dynamics.simulate import simulate
    from femkit.dynamics.topology import single_spring
    from femkit.errors import InstabilityError

    seen = []
    traj = simulate(single_spring(), "newmark", 1e-2, 0.25, record_every=3,
                    on_record=lambda k, t, x, v: seen.append((k, t, x, v)))
    assert [k for k, *_ in seen] == list(range(len(traj.times)))
    for k, t, x, v in seen:
        assert t == traj.times[k]
        np.testing.assert_array_equal(x, traj.x[k])
        np.testing.assert_array_equal(v, traj.v[k])
    seen.clear()
    with pytest.raises(InstabilityError) as info:
        simulate(single_spring(k=1e6), "explicit_euler", 1e-2, 5.0, check_stability=False,
                 on_record=lambda k, t, x, v: seen.append((k, t)))
    partial = info.value.partial
    assert [k for k, _ in seen] == list(range(len(partial.times)))
    assert [t for _, t in seen] == list(partial.times)
