"""Every VTU / PVD / PVTU / XDMF file femkit writes, read back by the readers its users have:
meshio (``meshio.read``, ``meshio.xdmf.TimeSeriesReader``) and VTK's own XML readers
(``vtkXMLUnstructuredGridReader``, ``vtkXMLPUnstructuredGridReader``), compared with what was
written (issue 30): points, cell blocks, VTK cell types, point and cell data.

The size sweep writes Poisson solutions on grids of 1..15 x 1..15 squares, with and without
boundary lines: 17 of those 450 sizes made meshio 5.3.5 refuse femkit's raw appended files
before the writer appended its arrays in reverse (femkit.mesh.vtk._appended_header).
"""

from __future__ import annotations

import json
import sys
import types
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest

vtk_xml = pytest.importorskip("vtkmodules.vtkIOXML",
                              reason="vtk (test extra) is not installed: pip install -e '.[test]'")
from vtkmodules import vtkCommonDataModel as vtk_cells  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared case
from _cloth import CLOTH as CLOTH_BASE  # noqa: E402

from femkit.case import case_from_dict  # noqa: E402
from femkit.case.poisson.output import write_solution  # noqa: E402
from femkit.mesh import Mesh, read_mesh  # noqa: E402
from femkit.mesh.structured import structured_box, structured_mesh  # noqa: E402

#: VTK's cell type numbers (vtkCellType.h), from VTK itself
VTK_TYPE = {"line": vtk_cells.VTK_LINE, "triangle": vtk_cells.VTK_TRIANGLE,
            "tetra": vtk_cells.VTK_TETRA}


def _vtk_read(path: Path, parallel: bool = False):
    """The grid VTK's XML reader gives for ``path``; any error or warning it raises fails."""
    reader = (vtk_xml.vtkXMLPUnstructuredGridReader() if parallel
              else vtk_xml.vtkXMLUnstructuredGridReader())
    events = []
    for kind in ("ErrorEvent", "WarningEvent"):
        reader.AddObserver(kind, lambda obj, event: events.append(event))
    reader.SetFileName(str(path))
    reader.Update()
    assert not events, f"VTK: {events} reading {path}"
    return reader.GetOutput()


def _vtk_array(data, name: str) -> np.ndarray:
    arr = data.GetArray(name)
    assert arr is not None, f"VTK finds no array {name!r}"
    return vtk_to_numpy(arr)


def _expect(path: Path, points, blocks, point_data=None, cell_data=None) -> None:
    """``path`` holds ``points`` (padded to 3D), the cell ``blocks`` ``[(type, conn)]``,
    ``point_data`` ``{name: array}`` and ``cell_data`` ``{name: [array per block]}``, as both
    meshio and VTK read it."""
    pts = np.zeros((len(points), 3))
    pts[:, :np.shape(points)[1]] = points
    point_data, cell_data = point_data or {}, cell_data or {}
    m = meshio.read(path)
    np.testing.assert_array_equal(m.points, pts)
    assert [c.type for c in m.cells] == [k for k, _ in blocks]
    for c, (_, conn) in zip(m.cells, blocks):
        np.testing.assert_array_equal(c.data, conn)
    for name, a in point_data.items():
        np.testing.assert_array_equal(np.asarray(m.point_data[name]).reshape(np.shape(a)), a)
    for name, per_block in cell_data.items():
        for got, a in zip(m.cell_data[name], per_block):
            np.testing.assert_array_equal(np.asarray(got).reshape(np.shape(a)), a)

    g = _vtk_read(path)
    assert g.GetNumberOfPoints() == len(pts)
    assert g.GetNumberOfCells() == sum(len(c) for _, c in blocks)
    np.testing.assert_array_equal(vtk_to_numpy(g.GetPoints().GetData()), pts)
    np.testing.assert_array_equal([g.GetCellType(c) for c in range(g.GetNumberOfCells())],
                                  np.concatenate([np.full(len(c), VTK_TYPE[k]) for k, c in blocks]))
    np.testing.assert_array_equal(vtk_to_numpy(g.GetCells().GetConnectivityArray()),
                                  np.concatenate([np.ravel(c) for _, c in blocks]))
    for name, a in point_data.items():
        np.testing.assert_array_equal(_vtk_array(g.GetPointData(), name).reshape(np.shape(a)), a)
    for name, per_block in cell_data.items():
        whole = np.concatenate([np.asarray(a) for a in per_block])
        np.testing.assert_array_equal(_vtk_array(g.GetCellData(), name).reshape(whole.shape), whole)


def _grid(nx: int, ny: int, lines: bool) -> Mesh:
    """``nx x ny`` squares of the unit square; ``lines=False``: no boundary lines (as a .msh
    with no physical lines gives)."""
    m = structured_mesh(nx, ny)
    return m if lines else Mesh(m.points, m.cells)


def _poisson_expected(mesh: Mesh, u, kappa):
    """The blocks and data of a Poisson solution file (femkit.case.poisson.output.write_solution):
    the cells and the tagged boundary facets, ``u`` on the points, ``tag``/``kappa`` on the
    cells (zeros on the facets) and the gmsh tags."""
    facet = {2: "line", 3: "triangle"}[mesh.dim]
    blocks = [({2: "triangle", 3: "tetra"}[mesh.dim], mesh.cells)]
    k = len(mesh.boundary_facets)
    if k:
        blocks.append((facet, mesh.boundary_facets))

    def per(a, zero):
        return [a, np.full(k, zero, np.asarray(a).dtype)] if k else [a]

    cells = {"tag": per(mesh.cell_tags, 0), "kappa": per(kappa, 0.0),
             "gmsh:physical": [mesh.cell_tags, mesh.boundary_tags] if k else [mesh.cell_tags]}
    return blocks, {"u": u}, cells


MESHES = {"5x5-points-no-lines": lambda: _grid(4, 4, False),   # the issue's 32 triangles
          "7x6-lines": lambda: _grid(7, 6, True),
          "box-2x3x2": lambda: structured_box(2, 3, 2)}


@pytest.mark.parametrize("compression", ["none", "zlib", "lzma"])
@pytest.mark.parametrize("which", sorted(MESHES))
def test_poisson_solution_vtu_reads_back_in_meshio_and_vtk(tmp_path, which, compression):
    mesh = MESHES[which]()
    u = np.sin(3 * mesh.points[:, 0]) + mesh.points[:, 1] ** 2
    kappa = 1.0 + np.arange(mesh.n_cells, dtype=float)
    path = write_solution(tmp_path / "solution.vtu", mesh, u, kappa, compression=compression)
    _expect(path, mesh.points, *_poisson_expected(mesh, u, kappa))


def test_the_issues_case_is_the_raw_layout_meshio_once_refused(tmp_path):
    """The 5 x 5-point grid without lines (32 triangles), constant kappa as a run writes it:
    the file meshio 5.3.5 refused, read back whole."""
    mesh = _grid(4, 4, False)
    assert (mesh.n_points, mesh.n_cells, len(mesh.boundary_facets)) == (25, 32, 0)
    u = mesh.points[:, 0] - 2 * mesh.points[:, 1]
    path = write_solution(tmp_path / "solution.vtu", mesh, u, 1.0)
    _expect(path, mesh.points, *_poisson_expected(mesh, u, np.ones(32)))


def test_poisson_solution_xdmf_reads_back_in_meshio(tmp_path):
    mesh = _grid(3, 2, True)
    u = mesh.points[:, 0] * 3
    write_solution(tmp_path / "solution.xdmf", mesh, u, 2.0)
    m = meshio.read(tmp_path / "solution.xdmf")
    assert [(c.type, len(c.data)) for c in m.cells] == [("triangle", 12), ("line", 10)]
    np.testing.assert_array_equal(m.point_data["u"], u)


def test_size_sweep_every_grid_reads_back_in_meshio_and_vtk(tmp_path):
    """450 sizes (1..15 x 1..15 squares, with and without boundary lines), among them the 17
    whose raw offsets clashed in meshio's reader with arrays appended in declared order:
    point and cell counts, cell types and ``u`` from both readers."""
    path = tmp_path / "solution.vtu"
    refused = []
    for nx in range(1, 16):
        for ny in range(1, 16):
            for lines in (False, True):
                mesh = _grid(nx, ny, lines)
                u = np.arange(mesh.n_points, dtype=float) * 0.5 - nx
                write_solution(path, mesh, u, 1.0)
                where = f"{nx}x{ny}{'+lines' if lines else ''}"
                g = _vtk_read(path)
                assert (g.GetNumberOfPoints(), g.GetNumberOfCells()) == (
                    mesh.n_points, mesh.n_cells + len(mesh.boundary_facets)), where
                np.testing.assert_array_equal(_vtk_array(g.GetPointData(), "u"), u, err_msg=where)
                try:
                    m = meshio.read(path)
                except BaseException:  # noqa: BLE001 (meshio calls sys.exit on failures)
                    refused.append(where)
                    continue
                assert [len(c.data) for c in m.cells] == [mesh.n_cells] + (
                    [len(mesh.boundary_facets)] if lines else []), where
                np.testing.assert_array_equal(m.point_data["u"], u, err_msg=where)
                np.testing.assert_array_equal(m.cell_data["kappa"][0], np.ones(mesh.n_cells))
    assert not refused, f"meshio refuses {len(refused)} of 450 sizes: {' '.join(refused)}"


@pytest.mark.parametrize("which", sorted(MESHES))
def test_femkit_reads_its_own_solution_vtu_as_a_mesh(tmp_path, which):
    """read what you write: the solution file as a mesh input gives the same points, cells,
    boundary facets and tag names."""
    mesh = MESHES[which]()
    path = write_solution(tmp_path / "solution.vtu", mesh, mesh.points[:, 0], 1.0)
    back = read_mesh(path)
    np.testing.assert_array_equal(back.points, mesh.points)
    np.testing.assert_array_equal(back.cells, mesh.cells)
    np.testing.assert_array_equal(back.boundary_facets, mesh.boundary_facets)
    np.testing.assert_array_equal(back.boundary_tags, mesh.boundary_tags)
    assert back.tag_names == mesh.tag_names


def test_a_vtu_in_the_old_layout_that_meshio_refuses_is_read_by_femkit(tmp_path):
    """The issue's solution.vtu as femkit wrote it before (arrays appended in declared order):
    meshio refuses it, VTK reads it, and femkit's mesh reader reads it (re-appended)."""
    from femkit.mesh.vtk import reappended

    mesh = _grid(4, 4, False)
    new = write_solution(tmp_path / "solution.vtu", mesh, mesh.points[:, 1], 1.0)
    old = tmp_path / "old.vtu"
    old.write_bytes(reappended(new.read_bytes(), reverse=False))
    with pytest.raises((Exception, SystemExit)):
        meshio.read(old)
    assert _vtk_read(old).GetNumberOfCells() == 32
    back = read_mesh(old)
    np.testing.assert_array_equal(back.points, mesh.points)
    np.testing.assert_array_equal(back.cells, mesh.cells)
    assert reappended(old.read_bytes()) == reappended(new.read_bytes())


@pytest.mark.parametrize("compression", ["zlib", None])
def test_reappended_leaves_files_without_raw_arrays_alone(tmp_path, compression):
    mesh = _grid(2, 2, True)
    if compression:
        path = write_solution(tmp_path / "s.vtu", mesh, mesh.points[:, 0], 1.0, compression="zlib")
    else:
        path = tmp_path / "s.vtu"
        meshio.write(path, meshio.Mesh(mesh.points, [("triangle", mesh.cells)]), binary=False)
    from femkit.mesh.vtk import reappended

    assert reappended(path.read_bytes()) is None


# ----------------------------------------------------------------------------- scenes

#: the scene-output tests' cloth (tests/case/_cloth.py), 6 frames, with its XDMF series
CLOTH = {**CLOTH_BASE, "t_end": 0.2,
         "output": {**CLOTH_BASE["output"], "xdmf": True, "png": False, "gif": False}}


#: a 2D scene with triangles: a gmsh disk falling onto the ground (cases/scenes/soft_disk.yaml, coarser)
DISK = {
    "problem": "mass_spring",
    "name": "disk",
    "system": {"type": "mesh", "geometry": "disk", "h": 0.15, "params": {"radius": 0.3},
               "origin": [0.0, 0.6], "k": 2000.0, "density": 10.0},
    "forces": {"gravity": 9.81, "ground": {"height": 0.0, "stiffness": 2.0e4}},
    "integrator": {"method": "symplectic_euler"},
    "dt": 0.001,
    "t_end": 0.01,
    "output": {"dir": "out", "every": 2, "xdmf": True, "png": False, "gif": False},
}


def _pvd(path: Path) -> list[tuple[float, str]]:
    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


@pytest.fixture(scope="module", params=["cloth-3d", "disk-2d"])
def cloth(request, tmp_path_factory):
    tmp = tmp_path_factory.mktemp(request.param)
    data = CLOTH if request.param == "cloth-3d" else DISK
    return tmp / "out", case_from_dict(data, base_dir=tmp).run(quiet=True)


def test_scene_frames_and_pvd_read_back_in_meshio_and_vtk(cloth):
    out, result = cloth
    traj, system, tri = result.trajectory, result.system, result.triangles
    listed = _pvd(out / "scene.pvd")
    assert [t for t, _ in listed] == [float(t) for t in traj.times] and len(listed) == 6
    i, j = system.springs[:, 0], system.springs[:, 1]
    for k, (_, name) in enumerate(listed):
        x = traj.x[k]
        stretch = np.linalg.norm(x[j] - x[i], axis=1) / system.rest - 1.0
        v = np.zeros((len(x), 3))
        v[:, :x.shape[1]] = traj.v[k]
        _expect(out / name, x, [("line", system.springs), ("triangle", tri)],
                point_data={"velocity": v, "pinned": system.pinned.astype(np.int32)},
                cell_data={})
        g = _vtk_read(out / name)
        np.testing.assert_allclose(_vtk_array(g.GetCellData(), "stretch")[:len(i)], stretch,
                                   rtol=0, atol=1e-14)


def test_triangle_scene_xdmf_series_reads_back_in_meshio(cloth):
    """``xdmf: true`` on a cloth (springs and triangles: XDMF's mixed topology): meshio's
    TimeSeriesReader gives both blocks and every step's positions and velocities."""
    out, result = cloth
    traj, system, tri = result.trajectory, result.system, result.triangles
    assert {"scene.xdmf", "scene.h5"} <= set(json.loads((out / "result.json").read_text())["files"])
    with meshio.xdmf.TimeSeriesReader(out / "scene.xdmf") as reader:
        points, cells = reader.read_points_cells()
        assert [c.type for c in cells] == ["line", "triangle"]
        np.testing.assert_array_equal(cells[0].data, system.springs)
        np.testing.assert_array_equal(cells[1].data, tri)
        np.testing.assert_array_equal(points[:, :traj.x.shape[2]], traj.x[0])
        assert reader.num_steps == len(traj.times)
        for k in range(reader.num_steps):
            t, point_data, _ = reader.read_data(k)
            assert t == pytest.approx(traj.times[k])
            d = traj.x.shape[2]
            np.testing.assert_array_equal(point_data["position"][:, :d], traj.x[k])
            np.testing.assert_array_equal(point_data["velocity"][:, :d], traj.v[k])


def test_springs_only_scene_xdmf_keeps_meshios_single_block(tmp_path):
    data = {**CLOTH, "system": {"type": "rope", "n": 6, "length": 1.0, "dim": 2, "k": 100.0,
                                "total_mass": 0.1, "pinned": "first"},
            "integrator": {"method": "symplectic_euler"}, "dt": 0.001, "t_end": 0.005}
    result = case_from_dict(data, base_dir=tmp_path).run(quiet=True)
    with meshio.xdmf.TimeSeriesReader(tmp_path / "out" / "scene.xdmf") as reader:
        _, cells = reader.read_points_cells()
        assert [c.type for c in cells] == ["line"]
        np.testing.assert_array_equal(cells[0].data, result.system.springs)


# ----------------------------------------------------------------------------- solids

def test_solid_frames_and_pvd_read_back_in_meshio_and_vtk(tmp_path):
    data = {"problem": "solid", "name": "cube", "mesh": {"geometry": "unit_cube", "h": 0.5},
            "material": {"model": "stable_neo_hookean", "E": 1000.0, "nu": 0.3, "density": 1.0},
            "boundaries": [{"tag": "xmin", "type": "fixed"},
                           {"tag": "xmax", "type": "traction", "traction": [0.0, 0.0, -1.0]}],
            "static": True, "output": {"png": False}}
    out = tmp_path / "out"
    result = case_from_dict(data, tmp_path).run(output_dir=out, quiet=True)
    body = result.problem.body
    listed = _pvd(out / "solid.pvd")
    assert len(listed) == len(result.x) >= 2
    region = np.asarray(result.problem.mesh.cell_tags, dtype=np.int32)
    for k, (_, name) in enumerate(listed):
        disp = np.zeros((len(body.rest_positions), 3))
        disp[:, :body.dim] = result.x[k] - body.rest_positions
        f = result.fields(k)
        _expect(out / name, body.rest_positions, [("tetra", body.rest.cells)],
                point_data={"displacement": disp},
                cell_data={"von_mises": [f["von_mises"]], "J": [f["J"]], "region": [region]})


# ----------------------------------------------------------------------------- distributed

def test_distributed_pieces_and_pvtu_index_read_back(tmp_path, monkeypatch):
    """write_pvtu as two ranks would (the PETSc gather replaced by the global vector): each
    piece reads back in meshio and VTK, and VTK's parallel reader joins them into the mesh."""
    import femkit.fem.distributed.pvtu as pvtu

    mesh = structured_mesh(5, 4)
    u = np.cos(mesh.points[:, 0]) * mesh.points[:, 1]
    monkeypatch.setattr(pvtu, "values_at", lambda vec, layout, nodes, comm: vec[nodes])
    comm = types.SimpleNamespace(tompi4py=lambda: types.SimpleNamespace(Barrier=lambda: None))
    halves = np.array_split(np.arange(mesh.n_cells), 2)
    for rank in (1, 0):
        layout = types.SimpleNamespace(rank=rank, size=2, elements=halves[rank])
        index = pvtu.write_pvtu(tmp_path, "solution", mesh, u, layout, comm)
    for rank, own in enumerate(halves):
        nodes, local = np.unique(mesh.cells[own], return_inverse=True)
        _expect(tmp_path / f"solution_p{rank}.vtu", mesh.points[nodes],
                [("triangle", local.reshape(-1, 3))], point_data={"u": u[nodes]},
                cell_data={"rank": [np.full(len(own), rank, np.int32)]})
    g = _vtk_read(index, parallel=True)
    assert g.GetNumberOfCells() == mesh.n_cells
    assert g.GetNumberOfPoints() == sum(len(np.unique(mesh.cells[h])) for h in halves)
    np.testing.assert_array_equal(np.sort(_vtk_array(g.GetCellData(), "rank")),
                                  np.repeat([0, 1], [len(h) for h in halves]))


def test_a_poisson_case_takes_its_own_solution_vtu_as_its_mesh(tmp_path):
    """The issue's run: a 5 x 5-point .msh with no boundary lines, ``u = 0`` on the whole
    boundary; its solution.vtu given back as the mesh of the same case gives the same ``u``."""
    from femkit.mesh import write_mesh

    write_mesh(tmp_path / "grid.msh", _grid(4, 4, False))
    case = {"problem": "poisson", "name": "grid", "mesh": {"file": "grid.msh"},
            "source": "2*pi**2*sin(pi*x)*sin(pi*y)", "solver": {"method": "direct"},
            "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
            "output": {"dir": "first", "vtu": True, "plot": False}}
    first = case_from_dict(case, tmp_path).run(quiet=True)
    case.update(mesh={"file": "first/solution.vtu"}, output={**case["output"], "dir": "second"})
    second = case_from_dict(case, tmp_path).run(quiet=True)
    assert second.mesh.n_cells == first.mesh.n_cells == 32
    np.testing.assert_array_equal(second.mesh.points, first.mesh.points)
    np.testing.assert_allclose(second.u, first.u, rtol=0, atol=1e-14)
    assert meshio.read(tmp_path / "second" / "solution.vtu").point_data["u"].shape == (25,)
