"""One kept-factor path (issue 16): the linear-solve session's kept factors and multigrid's
coarsest level (gmg-PCG and fmg) are made by :func:`femkit.solvers.kept_factor.factorize_kept`, and the
coarse solve it gives is exact (against SciPy's sparse LU)."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import femkit.solvers.kept_factor as kept
from femkit.fem import apply_dirichlet, assemble_load, assemble_stiffness
from femkit.mesh import MeshHierarchy, boundary_nodes, structured_mesh
from femkit.solvers import SolverSpec, solve


def _system(levels=3):
    H = MeshHierarchy.from_refinement(structured_mesh(4, 4), levels)  # 9 free coarse nodes
    m = H.finest
    return H, apply_dirichlet(assemble_stiffness(m), assemble_load(m, 1.0), boundary_nodes(m), 0.0)


@pytest.fixture
def calls(monkeypatch):
    seen = []
    original = kept.factorize_kept

    def counting(A, **kw):
        seen.append((A.shape, kw.get("method", "direct")))
        return original(A, **kw)

    monkeypatch.setattr(kept, "factorize_kept", counting)
    return seen


@pytest.mark.parametrize("method,pc", [("fmg", "none"), ("pcg", "gmg")], ids=["fmg", "gmg-pcg"])
def test_multigrid_coarse_solve_goes_through_the_kept_factor(calls, method, pc):
    H, sys = _system()
    where = dict(hierarchy=H, free=sys.free)
    kw = where if method == "fmg" else dict(preconditioner=pc, preconditioner_options=where)
    res = solve(sys.A, sys.b, method=method, **kw)
    assert res.converged and len(calls) == 1
    coarse = H.meshes[0]
    n_free = len(np.setdiff1d(np.arange(coarse.n_points), boundary_nodes(coarse)))
    assert calls[0] == ((n_free, n_free), "direct")


def test_session_kept_factor_goes_through_the_same_path(calls):
    _, sys = _system(3)
    factor = SolverSpec("direct").session().factorize(sys.A)
    assert calls == [(sys.A.shape, "direct")]
    b = np.stack([sys.b, np.arange(len(sys.b), dtype=float)], axis=1)
    ref = spla.splu(sp.csc_matrix(sys.A)).solve(b)
    assert np.allclose(factor.solve(b), ref, rtol=1e-12, atol=1e-14)
