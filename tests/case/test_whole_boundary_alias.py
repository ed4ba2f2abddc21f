"""`boundary` means the whole boundary for a mesh file without such a group, for Neumann
data as well as Dirichlet data (docs/case-files.md, `mesh`)."""

import meshio
import numpy as np
import pytest

from femkit.case.load import case_from_dict
from femkit.mesh import generate


def test_pure_neumann_on_whole_boundary_of_untagged_mesh_file(tmp_path):
    m = generate("unit_square", h=0.2)
    meshio.write(tmp_path / "bare.vtu",
                 meshio.Mesh(np.c_[m.points, np.zeros(m.n_points)], [("triangle", m.triangles)]))
    # u = x^2 + y^2 - x - y: -lap u = -4, du/dn = 1 on every side; int f + int h = -4 + 4 = 0
    case = case_from_dict({
        "problem": "poisson", "mesh": {"file": "bare.vtu"}, "source": "-4",
        "boundary": {"neumann": [{"tags": ["boundary"], "flux": 1}]},
        "exact": {"u": "x**2 + y**2 - x - y"}, "solver": {"method": "direct"},
    }, tmp_path)
    res = case.run(write=False, quiet=True)
    assert res.nullspace["relative_imbalance"] < 1e-12  # the flux covers the boundary once
    assert res.errors["max_nodal"] < 2e-2  # O(h^2) nodal error of P1 at h = 0.2
    assert res.errors["L2"] == pytest.approx(0, abs=1e-2)
