"""Topology builders: counts by formula, geometry, masses, pins, the SOFA scene."""

import numpy as np
import pytest

from femkit.dynamics.topology import FAMILIES, cloth_grid, mesh_edges, mesh_springs, rope, single_spring
from femkit.errors import InputError, MeshError
from femkit.mesh import Mesh


@pytest.mark.parametrize("nx, ny", [(2, 2), (3, 5), (7, 4)], ids=lambda v: str(v))
def test_cloth_family_counts(nx, ny):
    c = cloth_grid(nx, ny, 2.0, 1.0, k_structural=10.0, k_shear=4.0, k_bending=1.0)
    counts = np.bincount(c.family, minlength=4)
    assert counts[0] == (nx - 1) * ny + nx * (ny - 1)
    assert counts[1] == 2 * (nx - 1) * (ny - 1)
    assert counts[2] == (nx - 2) * ny + nx * (ny - 2)
    assert np.array_equal(c.k, np.array([10.0, 4.0, 1.0])[c.family])
    # rest lengths: grid spacing, diagonal, twice the spacing
    dx, dy = 2.0 / (nx - 1), 1.0 / (ny - 1)
    assert np.all(np.isclose(c.rest[c.family == 1], np.hypot(dx, dy)))
    allowed = [2 * dx, 2 * dy]
    assert np.all(np.isclose(c.rest[c.family == 2][:, None], allowed).any(axis=1))
    # no duplicate springs
    key = np.sort(c.springs, axis=1)
    assert len(np.unique(key, axis=0)) == c.n_springs
    # the cloth starts at rest
    assert np.abs(c.force(c.x0, c.v0)).max() < 1e-12


def test_cloth_families_left_out_and_taichi_count():
    c = cloth_grid(5, 5, 1.0, 1.0, k_structural=1.0)
    assert set(np.unique(c.family)) == {0}
    big = cloth_grid(128, 128, 1.0, 1.0, k_structural=1.0, k_shear=1.0, k_bending=1.0)
    # the 128 x 128 cloth of Taichi's mass-spring demo: 2*128*127 structural + 2*127*127 shear
    # + 2*128*126 bending springs
    assert big.n_springs == 2 * 128 * 127 + 2 * 127 * 127 + 2 * 128 * 126 == 97026
    assert FAMILIES[:3] == ("structural", "shear", "bending")


@pytest.mark.parametrize("plane, dim, axis", [("xz", 3, 2), ("xy", 3, 1), ("xy", 2, 1)], ids=["xz", "xy3", "xy2"])
def test_cloth_plane_and_pins(plane, dim, axis):
    c = cloth_grid(4, 3, 3.0, 2.0, k_structural=1.0, plane=plane, dim=dim, total_mass=6.0)
    assert c.dim == dim
    assert np.allclose(c.mass.sum(), 6.0)
    assert c.x0[:, axis].max() == 2.0 and c.x0[:, 0].max() == 3.0
    top = np.flatnonzero(c.pinned)
    assert np.allclose(c.x0[top, axis], 2.0) and np.allclose(sorted(c.x0[top, 0]), [0.0, 3.0])
    four = cloth_grid(4, 3, 3.0, 2.0, k_structural=1.0, pinned="corners", plane=plane, dim=dim)
    assert four.pinned.sum() == 4


def test_cloth_bad_input():
    with pytest.raises(InputError, match="nx"):
        cloth_grid(1, 3, 1.0, 1.0, k_structural=1.0)
    with pytest.raises(InputError, match="plane"):
        cloth_grid(3, 3, 1.0, 1.0, k_structural=1.0, dim=2, plane="xz")
    with pytest.raises(InputError, match="pinned"):
        cloth_grid(3, 3, 1.0, 1.0, k_structural=1.0, pinned="left")
    with pytest.raises(InputError, match="either"):
        cloth_grid(3, 3, 1.0, 1.0, k_structural=1.0, mass=1.0, total_mass=2.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_rope(dim):
    r = rope(6, 2.5, k=7.0, dim=dim, total_mass=3.0, pinned="both")
    assert r.n == 6 and r.n_springs == 5 and r.dim == dim
    assert np.allclose(r.rest, 0.5) and np.allclose(r.mass, 0.5) and np.allclose(r.k, 7.0)
    assert r.pinned.tolist() == [True, False, False, False, False, True]
    assert np.array_equal(r.springs, np.stack([np.arange(5), np.arange(1, 6)], 1))


def square_mesh(n=4):
    """Structured unit square, each cell split into two CCW triangles (no gmsh needed)."""
    g = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(g, g)
    pts = np.stack([X.ravel(), Y.ravel()], 1)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tri = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    bottom = np.stack([idx[0, :-1], idx[0, 1:]], 1)
    return Mesh(pts, tri, boundary_edges=bottom, boundary_tags=np.full(len(bottom), 3),
                tag_names={"bottom": 3})


def test_mesh_springs_masses_edges_and_pins():
    mesh = square_mesh(4)
    s = mesh_springs(mesh, k=5.0, density=3.0, thickness=0.5, pinned="bottom")
    assert s.mass.sum() == pytest.approx(3.0 * 0.5 * 1.0)
    # Euler for a triangulated disk: E = V + F - 1
    assert s.n_springs == mesh.n_points + mesh.n_triangles - 1
    assert np.flatnonzero(s.pinned).tolist() == [0, 1, 2, 3, 4]
    # corner (0,0) touches two triangles of area 1/32 each: mass 1.5 * 2/32 / 3
    assert s.mass[0] == pytest.approx(1.5 * (2 / 32) / 3)
    s3 = mesh_springs(mesh, k=5.0, dim=3)
    assert s3.dim == 3 and np.all(s3.x0[:, 2] == 0)


def test_mesh_springs_on_gmsh_disk():
    pytest.importorskip("gmsh")
    from femkit.mesh import generate

    mesh = generate("disk", 0.3)
    s = mesh_springs(mesh, k=1.0, density=2.0)
    assert s.mass.sum() == pytest.approx(2.0 * mesh.areas().sum(), rel=1e-12)
    assert np.abs(s.force(s.x0, s.v0)).max() < 1e-12


def test_mesh_edges_and_lonely_node():
    assert mesh_edges(np.array([[0, 1, 2]])).tolist() == [[0, 1], [0, 2], [1, 2]]
    mesh = Mesh(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [5.0, 5.0]]), np.array([[0, 1, 2]]))
    with pytest.raises(MeshError, match=r"\[3\]"):
        mesh_springs(mesh, k=1.0)


def test_single_spring_sofa_scene():
    s = single_spring(k=100.0, m=10.0)
    assert s.x0.tolist() == [[0.0, 2.0], [0.0, 1.0]] and s.rest.tolist() == [1.0]
    # at rest, only gravity acts: m g downward; equilibrium y = 1 - m g / k = 0
    assert np.allclose(s.force(s.x0, s.v0), [[0, 0], [0, -100.0]])
    eq = np.array([[0.0, 2.0], [0.0, 0.0]])
    assert np.allclose(s.force(eq, s.v0), 0.0)
    assert single_spring(gravity=None).forces == ()
    assert single_spring(dim=3).x0[1].tolist() == [0.0, 1.0, 0.0]
