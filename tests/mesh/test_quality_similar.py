"""A red-refined triangle mesh takes its quality numbers from its root's (the four children
are similar to their parent): equal to a pass over its own triangles to 1e-12, through the
compiled refinement, the renumbered hierarchy and a renumbering; never for tetrahedra or for a
mesh built anew from the refined arrays."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from femkit.mesh import Mesh, generate, quality, refine
from femkit.mesh.hierarchy import MeshHierarchy
from femkit.mesh.renumber import permute_nodes

QM = sys.modules["femkit.mesh.quality"]   # the module (the package's ``quality`` is the function)
_SIMILAR = QM._SIMILAR


def _direct(mesh):
    """The numbers of a pass over the mesh itself (a new Mesh object: nothing noted)."""
    fresh = Mesh(mesh.points, mesh.cells, cell_tags=mesh.cell_tags)
    assert fresh not in _SIMILAR
    return quality(fresh)


def _assert_close(q, ref):
    assert q.keys() == ref.keys()
    for key, value in ref.items():
        assert q[key] == pytest.approx(value, rel=1e-12, abs=0.0), key


@pytest.mark.parametrize("levels", [1, 2, 4])
@pytest.mark.parametrize("geometry", ["unit_square", "l_shape", "disk"])
def test_refined_numbers_equal_a_pass(geometry, levels):
    mesh = refine(generate(geometry, 0.2), levels)
    assert mesh in _SIMILAR
    _assert_close(quality(mesh), _direct(mesh))


def test_perturbed_root_gives_distinct_angles_and_they_are_inherited():
    base = generate("unit_square", 0.25)
    rng = np.random.default_rng(2)
    pts = base.points.copy()
    inner = ((pts > 1e-9) & (pts < 1 - 1e-9)).all(axis=1)
    pts[inner] += 0.05 * rng.uniform(-1, 1, (int(inner.sum()), 2))
    root = Mesh(pts, base.cells, boundary_edges=base.boundary_edges,
                boundary_tags=base.boundary_tags, tag_names=base.tag_names)
    fine = refine(root, 3)
    q, ref = quality(fine), _direct(fine)
    _assert_close(q, ref)
    assert q["min_angle"] == pytest.approx(quality(root)["min_angle"], rel=1e-12)
    assert q["h_max"] == pytest.approx(quality(root)["h_max"] / 8, rel=1e-12)


def test_hierarchy_levels_and_a_renumbering_keep_the_record():
    hier = MeshHierarchy.from_refinement(generate("unit_square", 0.2), 3, renumber="rcm")
    for mesh in hier.meshes[1:]:
        assert mesh in _SIMILAR
        _assert_close(quality(mesh), _direct(mesh))
    fine = hier.meshes[-1]
    perm = np.random.default_rng(0).permutation(fine.n_points)
    moved = permute_nodes(fine, perm, sort_elements=True)
    _assert_close(quality(moved), _direct(moved))


def test_large_root_and_tetrahedra_are_computed_directly(monkeypatch):
    monkeypatch.setattr(QM, "SIMILAR_ROOT_MAX", 10)
    assert refine(generate("unit_square", 0.2), 1) not in _SIMILAR   # root above the bound
    from femkit.mesh import structured_box

    assert refine(structured_box(2, 2, 2), 1) not in _SIMILAR        # Bey's children differ


def test_the_compiled_interleaved_refinement_notes_it_too():
    from femkit.mesh.refine import refine_interleaved

    fine, _, _ = refine_interleaved(refine(generate("l_shape", 0.2), 1))
    assert fine in _SIMILAR and _SIMILAR[fine][1] == 2
    _assert_close(quality(fine), _direct(fine))
