"""The mass-spring patterns on femkit's one assembly stack (:mod:`femkit.fem.sparsity`) equal a
straightforward construction written here: ``np.unique`` over the ``(row, column)`` keys of the
springs' ``d x d`` blocks, the diagonal (or every node's diagonal block) and a declared force's
CSR structure, restricted to the free dofs -- array for array, so the values written through them
are the same bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.dynamics.forces import Gravity, GroundContact
from femkit.dynamics.forces.elastic import ElasticForce
from femkit.dynamics.forces.jacobian import SpringPattern
from femkit.dynamics.kernels.assembly import FreePattern, assemble_with_forces, contact_values
from femkit.dynamics.system import MassSpringSystem
from femkit.dynamics.topology import cloth_grid
from femkit.fem.sparsity import BlockPattern, restrict_structure, union_structures
from femkit.mesh.structured import structured_box
from femkit.solids import ElasticBody, material


def _block_keys(i, j, d):
    """Rows and columns of the blocks (i, i), (j, j), (i, j), (j, i) of springs (i, j), each
    (s, d*d) with entry p*d + q."""
    p, q = np.repeat(np.arange(d), d), np.tile(np.arange(d), d)
    rows = [a[:, None] * d + p for a in (i, j, i, j)]
    cols = [b[:, None] * d + q for b in (i, j, j, i)]
    return rows, cols


def _reference(system):
    """The free pattern by np.unique: (indptr, indices, slots, diag, {force: (inside, slots)})."""
    d, n, ndof = system.dim, system.n, system.ndof
    i, j = system.springs[:, 0].astype(np.int64), system.springs[:, 1].astype(np.int64)
    rows, cols = _block_keys(i, j, d)
    nodes = np.arange(n)
    rows.append(_block_keys(nodes, nodes, d)[0][0])          # every node's diagonal block
    cols.append(_block_keys(nodes, nodes, d)[1][0])
    owners = []
    for k, f in enumerate(system.forces):
        st = f.structure()
        if st is not None:
            rows.append(np.repeat(np.arange(ndof), np.diff(st[0])))
            cols.append(np.asarray(st[1], dtype=np.int64))
            owners.append(k)
    free = system.free_dofs
    new = np.full(ndof, -1)
    new[free] = np.arange(len(free))
    fr = new[np.concatenate([r.ravel() for r in rows])]
    fc = new[np.concatenate([c.ravel() for c in cols])]
    ok = (fr >= 0) & (fc >= 0)
    nf = len(free)
    keys, inv = np.unique(fr[ok] * nf + fc[ok], return_inverse=True)
    slot = np.full(len(fr), -1)
    slot[ok] = inv
    indptr = np.concatenate([[0], np.cumsum(np.bincount(keys // nf, minlength=nf))])
    parts = np.split(slot, np.cumsum([r.size for r in rows])[:-1])
    diag = np.searchsorted(keys, np.arange(nf) * (nf + 1))
    forces = {k: (np.flatnonzero(s >= 0), s[s >= 0]) for k, s in zip(owners, parts[5:])}
    return indptr, keys % nf, np.stack([s.reshape(-1, d * d) for s in parts[:4]]), diag, forces


def _assert_same(pat, system):
    indptr, indices, slots, diag, forces = _reference(system)
    assert np.array_equal(pat.indptr, indptr) and pat.indptr.dtype == np.int32
    assert np.array_equal(pat.indices, indices) and pat.indices.dtype == np.int32
    assert np.array_equal(pat.slots, slots)
    assert np.array_equal(pat.diag, diag)
    assert pat.force_slots.keys() == forces.keys()
    for k, (inside, where) in forces.items():
        assert np.array_equal(pat.force_slots[k][0], inside)
        assert np.array_equal(pat.force_slots[k][1], where)


def _cloth():
    """A 7 x 7 cloth, its top corners pinned and one node held in z only (a roller)."""
    system = cloth_grid(7, 7, 1.0, 1.0, k_structural=200.0, k_shear=50.0, k_bending=10.0,
                        total_mass=1.0, pinned="top_corners", forces=[Gravity(9.81), GroundContact(100.0)])
    held = system.pinned_dofs.copy()
    held[24, 2] = True
    return MassSpringSystem(system.x0, system.mass, system.springs, system.k, system.rest,
                            pinned=held, forces=system.forces)


def _springs_and_solid():
    """An elastic block with springs across it, two nodes pinned: the force's structure and the
    spring blocks overlap in some node pairs and not in others."""
    mesh = structured_box(3, 2, 2, (3.0, 1.0, 1.0))
    body = ElasticBody.from_mesh(mesh, material("stable_neo_hookean", E=1e3, nu=0.3, density=1.0))
    springs = np.array([[0, 5], [3, 7], [1, mesh.n_points - 1], [2, 3]])
    return MassSpringSystem(body.rest_positions, body.lumped_masses(), springs, 10.0,
                            pinned=[0, 2], forces=[Gravity(9.81), ElasticForce(body)])


@pytest.mark.parametrize("build", [_cloth, _springs_and_solid], ids=["cloth", "springs+solid"])
def test_free_pattern_is_the_unique_construction(build):
    system = build()
    pat = FreePattern(system)
    _assert_same(pat, system)
    # and the values written through it are the ones written through the reference slots
    x = system.x0 + 0.01 * np.random.default_rng(3).standard_normal(system.x0.shape)
    m = np.repeat(system.mass, system.dim)
    data, _, _ = assemble_with_forces(pat, system, x, np.zeros_like(x), 0.0, diagonal=m,
                                      kcoef=0.01, dcoef=0.0, fix="clamp")
    K = sp.csr_matrix(system.mass_matrix() + 0.01 * system.stiffness_matrix(x, fix="clamp"))
    ref = K[system.free_dofs][:, system.free_dofs].toarray()
    assert np.abs(pat.matrix(data).toarray() - ref).max() <= 1e-12 * np.abs(ref).max()


def _pair_matrix(system, pairs, stream):
    """A symmetric ``nd x nd`` matrix with a random dense ``d x d`` block on every node pair
    ``(a, b)`` of ``pairs`` and its transpose on ``(b, a)`` (a contact Hessian's couplings)."""
    d, rng = system.dim, np.random.default_rng(stream)
    B = np.zeros((system.ndof, system.ndof))
    for a, b in pairs:
        blk = rng.standard_normal((d, d))
        B[a * d:a * d + d, b * d:b * d + d] += blk
        B[b * d:b * d + d, a * d:a * d + d] += blk.T
    return sp.csr_matrix(B)


def test_contact_pattern_holds_the_newton_matrix_and_follows_the_contact_set():
    """Far node pairs (a pinned node's and the roller's among them) join the free pattern; the
    values are the free rows and columns of the sum; a pattern that holds a call's couplings is
    kept (the same object: the factor's analysis reused), one that does not is rebuilt from them
    and the pairs used since the last build, so a pair out of contact since then leaves it."""
    system = _cloth()
    pat, free, cache = FreePattern(system), system.free_dofs, {}
    x = system.x0 + 0.01 * np.random.default_rng(5).standard_normal(system.x0.shape)
    m = np.repeat(system.mass, system.dim)
    base, _, _ = assemble_with_forces(pat, system, x, np.zeros_like(x), 0.0, diagonal=m,
                                      kcoef=0.01, dcoef=0.0, fix="clamp")
    K = sp.csr_matrix(system.mass_matrix() + 0.01 * system.stiffness_matrix(x, fix="clamp"))
    A, P, Q, R = (0, 40), (6, 24), (3, 45), (10, 38)   # node 6: a pinned corner; 24: the roller
    seen = []
    for k, pairs in enumerate(([A, P], [A], [Q], [R])):
        B = _pair_matrix(system, pairs, k)
        cp, data = contact_values(pat, base, [None, B], 0.5, cache)
        ref = (K + 0.5 * B)[free][:, free].toarray()
        assert np.abs(cp.matrix(data).toarray() - ref).max() <= 1e-12 * np.abs(ref).max()
        seen.append(cp)
    n = system.n
    key = lambda a, b: a * n + b
    assert seen[1] is seen[0] and seen[2] is not seen[1] and seen[3] is not seen[2]
    assert {key(*A), key(*P), key(*Q)} <= set(seen[2].pairs)          # A, P used since build 1
    assert key(*A) not in set(seen[3].pairs) and key(*Q) in set(seen[3].pairs)
    assert not np.isin(seen[3].extra_pairs, [key(*A), key(*A[::-1])]).any()


def test_spring_pattern_is_the_unique_construction():
    """Springs' blocks plus the diagonal entries only (node 5 has no spring: no block)."""
    i, j, n, d = np.array([0, 1, 3, 0]), np.array([1, 2, 4, 4]), 6, 2
    rows, cols = _block_keys(i, j, d)
    r = np.concatenate([a.ravel() for a in rows] + [np.arange(n * d)])
    c = np.concatenate([a.ravel() for a in cols] + [np.arange(n * d)])
    keys, inv = np.unique(r * (n * d) + c, return_inverse=True)
    pat = SpringPattern(n, d, i, j)
    assert np.array_equal(pat.indices, keys % (n * d))
    assert np.array_equal(pat.indptr, np.searchsorted(keys, np.arange(n * d + 1) * (n * d)))
    assert np.array_equal(pat._inv, inv)
    assert pat.indptr[-1] - pat.indptr[-3] == 2          # node 5: two diagonal entries


def test_block_pattern_is_the_blocked_cell_pattern():
    cells = np.array([[0, 1, 2], [1, 3, 2], [4, 2, 3]])
    pat = BlockPattern(cells, 5, 3)
    blocked = (cells[:, :, None] * 3 + np.arange(3)).reshape(3, -1)
    keys = np.unique(np.repeat(blocked, 9, axis=1).ravel() * 15 + np.tile(blocked, (1, 9)).ravel())
    assert np.array_equal(pat.indices, keys % 15)
    assert np.array_equal(pat.indptr, np.searchsorted(keys, np.arange(16) * 15))


def test_restrict_and_union_against_scipy():
    rng = np.random.default_rng(5)
    A = sp.random(30, 30, density=0.2, random_state=rng, format="csr") + sp.eye(30, format="csr")
    B = sp.random(30, 30, density=0.1, random_state=rng, format="csr")
    for M in (A, B):
        M.sort_indices()
    keep = np.flatnonzero(rng.random(30) < 0.7)
    ip, ix, moved = restrict_structure(A.indptr, A.indices, keep)
    R = A[keep][:, keep]
    R.sort_indices()
    assert np.array_equal(ip, R.indptr) and np.array_equal(ix, R.indices)
    assert np.array_equal(A.data[moved >= 0], R.data)          # every kept entry moved in order
    ip, ix, (pa, pb) = union_structures([(A.indptr, A.indices), (B.indptr, B.indices)], 30)
    U = (abs(A) + abs(B)).tocsr()
    U.sort_indices()
    assert np.array_equal(ip, U.indptr) and np.array_equal(ix, U.indices)
    rows_a = np.repeat(np.arange(30), np.diff(A.indptr))
    assert np.array_equal(ix[pa], A.indices) and np.array_equal(np.searchsorted(ip, pa, "right") - 1, rows_a)
    rows_b = np.repeat(np.arange(30), np.diff(B.indptr))
    assert np.array_equal(ix[pb], B.indices) and np.array_equal(np.searchsorted(ip, pb, "right") - 1, rows_b)
