"""solution.vtu holds the estimator's indicator of each cell as cell data ``eta`` (P1 and P2,
raw appended and compressed), read back equal to the run's ``result.indicators`` by meshio and
by VTK's XML reader; the writer thread fills the array's bytes after the rest of the file
(femkit.mesh.vtk.Later), and an abandoned file makes the waiting writer fail at once."""

from __future__ import annotations

import threading
import time

import meshio
import numpy as np
import pytest

from femkit.case.load import case_from_dict
from femkit.errors import MeshError
from femkit.mesh.vtk import Later, write_cells

CASE = {
    "problem": "poisson",
    "mesh": {"geometry": "l_shape", "h": 0.25},
    "source": "1",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "0"}]},
    "solver": {"method": "direct"},
}


def _vtk_cell_array(path, name: str) -> np.ndarray:
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    array = reader.GetOutput().GetCellData().GetArray(name)
    assert array is not None, f"VTK finds no cell array {name!r} in {path}"
    return vtk_to_numpy(array)


@pytest.mark.parametrize("element, compression", [("P1", "none"), ("P2", "none"),
                                                  ("P1", "zlib")])
def test_solution_vtu_holds_the_indicators_as_cell_data_eta(tmp_path, element, compression):
    out = tmp_path / "out"
    case = case_from_dict(dict(CASE, element=element, output={
        "dir": str(out), "vtu": True, "plot": False, "compression": compression}))
    result = case.run(quiet=True)
    eta = np.asarray(result.indicators)
    assert eta.shape == (result.mesh.n_cells,) and eta.min() > 0  # a real estimate
    m = meshio.read(out / "solution.vtu")
    block = "triangle" if element == "P1" else "triangle6"
    k = [c.type for c in m.cells].index(block)
    np.testing.assert_array_equal(m.cell_data["eta"][k], eta)
    np.testing.assert_array_equal(m.point_data["u"], result.u)  # the rest is as before
    # VTK's reader: the cells come first in the file's blocks, any boundary lines after them
    np.testing.assert_array_equal(_vtk_cell_array(out / "solution.vtu", "eta")[:len(eta)], eta)


def test_the_writer_fills_the_hole_when_the_values_come(tmp_path):
    """The raw appended writer writes everything else first and waits for the Later array;
    the file is complete and exact once it is handed over from another thread."""
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    cells = [("triangle", np.array([[0, 1, 2], [1, 3, 2]]))]
    late = Later(2)
    done = threading.Event()

    def write():
        write_cells(tmp_path / "a.vtu", points, cells, point_data={"u": np.arange(4.0)},
                    cell_data={"eta": [late]})
        done.set()

    worker = threading.Thread(target=write)
    worker.start()
    time.sleep(0.2)
    assert not done.is_set()  # waiting for the values
    late.set([0.25, 0.5])
    worker.join(5)
    assert done.is_set()
    np.testing.assert_array_equal(meshio.read(tmp_path / "a.vtu").cell_data["eta"][0], [0.25, 0.5])
    np.testing.assert_array_equal(_vtk_cell_array(tmp_path / "a.vtu", "eta"), [0.25, 0.5])


def test_an_abandoned_array_fails_its_waiting_writer_and_a_wrong_length_is_refused():
    late = Later(3)
    with pytest.raises(MeshError, match="3 rows was given 2"):
        late.set([1.0, 2.0])
    threading.Timer(0.1, late.abandon).start()
    t0 = time.perf_counter()
    with pytest.raises(MeshError, match="abandoned"):
        late.get()
    assert time.perf_counter() - t0 < 2
