"""solution.vtu is written by a writer thread beside the errors and the estimate
(femkit.case.poisson.output.SolutionFile): the output directory still appears whole or not at
all, a failure after the solve leaves nothing behind, and the writer's own error is a femkit
error naming the file."""

import threading

import meshio
import numpy as np
import pytest

import femkit.case.poisson.estimate as estimate_module
import femkit.case.poisson.output as output_module
from femkit.case.load import case_from_dict
from femkit.errors import FemkitError, MeshError

CASE = {
    "problem": "poisson",
    "mesh": {"geometry": "unit_square", "h": 0.25, "refine": 1},
    "source": "1",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "x"}]},
    "exact": {"u": "x", "grad": ["1 + 0 * x", "0 * y"]},
    "solver": {"method": "direct"},
}


def _case(tmp_path):
    return case_from_dict(dict(CASE, output={"dir": str(tmp_path / "out"), "vtu": True}))


def _left_in(parent):
    return sorted(p.name for p in parent.iterdir())


def test_the_file_is_written_by_another_thread_and_moved_in_whole(tmp_path, monkeypatch):
    threads = []
    write = output_module.write_solution

    def spy(path, *args):
        threads.append((threading.current_thread() is threading.main_thread(), path.parent.name))
        return write(path, *args)

    monkeypatch.setattr(output_module, "write_solution", spy)
    result = _case(tmp_path).run(quiet=True)
    assert threads and not threads[0][0]             # not the main thread
    assert threads[0][1].startswith("out.tmp-")      # staged beside the output directory
    assert _left_in(tmp_path) == ["out"]             # nothing staged is left behind
    out = tmp_path / "out"
    assert {"result.json", "solution.vtu", "solution.vtu.tags.json"} <= set(_left_in(out))
    m = meshio.read(out / "solution.vtu")
    np.testing.assert_array_equal(m.point_data["u"], result.u)
    np.testing.assert_array_equal(m.cells_dict["triangle"], result.mesh.cells)


def test_a_failure_after_the_solve_writes_nothing(tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise MeshError("estimate broke on purpose")

    monkeypatch.setattr(estimate_module, "estimate_facts", broken)
    with pytest.raises(MeshError, match="on purpose"):
        _case(tmp_path).run(quiet=True)
    assert _left_in(tmp_path) == []                  # neither the directory nor the staged file


def test_the_writers_error_is_a_femkit_error_and_nothing_is_written(tmp_path, monkeypatch):
    def unwritable(path, *args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(output_module, "write_solution", unwritable)
    with pytest.raises(FemkitError, match="solution writer failed: OSError.*No space left"):
        _case(tmp_path).run(quiet=True)
    assert _left_in(tmp_path) == []
