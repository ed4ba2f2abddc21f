"""The implicit methods' matrices assembled by one compiled pass into a cached pattern.

:class:`FreePattern` is built once per system (topology and pinned set) by femkit's one assembly
stack, :mod:`femkit.fem.sparsity`: the CSR pattern of the spring matrices (every spring's four
``d x d`` blocks plus every node's diagonal block,
:class:`~femkit.dynamics.forces.jacobian.SpringPattern` with ``node_blocks``) joined to the declared
forces' fixed structures (:func:`~femkit.fem.sparsity.union_structures`) and restricted to the free
dofs (:func:`~femkit.fem.sparsity.restrict_structure`), and for every spring block entry its slot in
that CSR ``data`` array (``-1`` where the row or column is pinned). A step then only writes
values: :meth:`FreePattern.assemble` fills ``data`` with the diagonal, adds every spring's Hessian
(with the definiteness fix) and dashpot blocks in one pass
(:func:`~femkit.dynamics.kernels.spring_kernels.hessian_values`), and adds the declared forces' own
matrices (contact stiffness, viscous damping: nodal blocks, inside the pattern) by a sorted merge,
or -- a force with a fixed structure, an elastic solid's Hessian -- by a slot map built with the
pattern. The pattern never changes, so the Cholesky factorisation reuses one symbolic analysis for
the whole run (:meth:`femkit.solvers.cholesky.CholeskyFactor.refactor`); a force matrix with an
entry outside the pattern is reported (``None``), and the caller falls back to the general path.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["FreePattern", "free_pattern", "ContactPattern", "contact_values"]


class _FreeDofPattern:
    """The interface :meth:`femkit.solvers.session.LinearSession.solve_on_pattern` and the
    assembly read of a CSR pattern on the free dofs: ``indptr``, ``indices``, ``free``, ``shape``,
    ``dim`` and ``coordinate_pair`` set by the subclass."""

    @property
    def entry_group(self) -> np.ndarray:
        """The group of each entry for :meth:`femkit.solvers.session.LinearSession.solve_on_pattern`:
        its coordinate pair (groups that stay all zero, e.g. the out-of-plane couplings of a
        planar cloth, are left out of the factor)."""
        return self.coordinate_pair

    @property
    def n_groups(self) -> int:
        """Number of coordinate pairs, ``d * d``."""
        return self.dim * self.dim

    @property
    def kept_groups(self) -> np.ndarray:
        """The same-coordinate pairs ``(p, p)``, always factorised (the clamp zeroes and restores
        them spring by spring)."""
        return np.arange(self.dim) * (self.dim + 1)

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """The CSR matrix with these values (the pattern arrays are shared, not copied)."""
        return sp.csr_matrix((data, self.indices, self.indptr), shape=self.shape)

    def add(self, data: np.ndarray, B, scale: float = 1.0) -> bool:
        """``data += scale * B[free][:, free]`` for a full ``ndof x ndof`` sparse ``B`` inside the
        pattern; False when ``B`` has an entry outside it (``data`` is then unusable)."""
        from .spring_kernels import add_csr_into

        Bf = sp.csr_matrix(B)[self.free][:, self.free].tocsr()
        Bf.sort_indices()
        return bool(add_csr_into(self.indptr, self.indices, data, Bf.indptr.astype(np.int32),
                                 Bf.indices.astype(np.int32), Bf.data, float(scale)))


def _coordinate_pairs(free: np.ndarray, indptr: np.ndarray, indices: np.ndarray,
                      d: int) -> np.ndarray:
    """``p*d + q`` of every entry of a free-dof CSR pattern: the coordinates it couples."""
    coord = free % d
    rows = np.repeat(np.arange(len(free)), np.diff(indptr))
    return (coord[rows] * d + coord[indices]).astype(np.int8)


class FreePattern(_FreeDofPattern):
    """CSR pattern of the implicit methods' matrices on the free dofs, with the scatter slots.

    The pattern holds every spring's four ``d x d`` blocks, every node's full ``d x d``
    diagonal block (so nodal force matrices, e.g. contact stiffness or viscous damping, always
    fit) and the fixed structure a declared force states (:meth:`Force.structure
    <femkit.dynamics.forces.base.Force.structure>`: an elastic body's CSR pattern, whose values
    are then written by slot, ``force_slots``), restricted to the free dofs.

    Attributes
    ----------
    indptr, indices : int32 arrays of the restricted CSR pattern (sorted columns).
    slots : (4, s, d*d) int64, the ``data`` position of each spring block entry (or -1):
        blocks ``(i, i)``, ``(j, j)``, ``(i, j)``, ``(j, i)``, entry ``p*d + q``.
    diag : (n_free_dofs,) int64, the ``data`` position of each diagonal entry.
    coordinate_pair : (nnz,) int8, ``p*d + q`` for an entry coupling coordinate ``p`` of one node
        with coordinate ``q`` of another (or the same) node.
    free : the free dofs (``system.free_dofs``).
    """

    def __init__(self, system):
        from ...fem.sparsity import restrict_structure, union_structures
        from ..forces.jacobian import SpringPattern

        free = system.free_dofs
        # the spring blocks and every node's diagonal block
        springs = SpringPattern(system.n, system.dim, system._i, system._j, node_blocks=True)
        # declared forces with a fixed matrix structure (an elastic body's CSR pattern), joined
        # to the springs' (a merge of sorted keys), then the pattern on the free dofs
        structured = [(k, f.structure()) for k, f in enumerate(system.forces)]
        structured = [(k, st) for k, st in structured if st is not None]
        indptr, indices, (in_union, *own) = union_structures(
            [(springs.indptr, springs.indices), *(st for _, st in structured)], system.ndof)
        indptr, indices, moved = restrict_structure(indptr, indices, free)
        spring_moved = moved[in_union]
        self.slots = spring_moved[springs.slots]
        self.diag = spring_moved[springs.diag[free]]
        #: force index -> (entries of its structure inside the free pattern, their data slots)
        self.force_slots = {}
        for (k, _), at in zip(structured, own):
            part = moved[at]
            inside = np.flatnonzero(part >= 0)
            self.force_slots[k] = (inside, part[inside])
        nf = len(free)
        d = system.dim
        self.indices = indices.astype(np.int32)
        self.indptr = indptr.astype(np.int32)
        self.nnz = len(indices)
        # the coordinate pair (p, q) -> p*d + q an entry couples (see entry_group)
        self.coordinate_pair = _coordinate_pairs(free, self.indptr, self.indices, d)
        self.dim = d
        self.free = free
        self.shape = (nf, nf)
        self.ndof = system.ndof

    def assemble(self, system, x, *, diagonal, kcoef: float, ccoef: float = 0.0,
                 clamp: bool = False, v=None, want_force: bool = False,
                 want_kv: bool = False):
        """Values ``diag(diagonal) + kcoef K_springs(x) + ccoef D_dashpots(x)`` on the free dofs,
        and in the same pass (optional) the spring forces (Hooke + dashpots with ``v``) and the
        product ``K_springs(x) v``, both ``(n, d)`` over all nodes.

        ``diagonal``: flat ``(ndof,)`` values added on the diagonal (e.g. ``a_m m``).
        Returns ``(data, force or None, kv or None)``.
        """
        from .spring_kernels import hessian_values

        data = np.zeros(self.nnz)
        data[self.diag] = np.asarray(diagonal, dtype=float)[self.free]
        n, d = system.n, system.dim
        vv = np.zeros((0, d)) if v is None else np.ascontiguousarray(v, dtype=float)
        force = np.zeros((n, d)) if want_force else np.zeros((0, d))
        kv = np.zeros((n, d)) if want_kv else np.zeros((0, d))
        if system.n_springs:
            if (want_force or want_kv) and v is None:
                vv = np.zeros((n, d))
            hessian_values(np.ascontiguousarray(x, dtype=float), vv, system._i, system._j,
                           system.k, system.rest, system.damping, float(system.length_floor),
                           bool(clamp), float(kcoef), float(ccoef), self.slots, data, force, kv)
        return data, (force if want_force else None), (kv if want_kv else None)


def free_pattern(system, cache: dict) -> FreePattern:
    """The :class:`FreePattern` of ``system`` kept in ``cache`` (a run's ``ctx.cache``), rebuilt
    when the system, its springs or its pinned set are other objects."""
    key = (system, system.springs, system.pinned_dofs)
    kept = cache.get("free_pattern")
    if kept is not None and all(a is b for a, b in zip(kept[0], key)):
        return kept[1]
    pat = FreePattern(system)
    cache["free_pattern"] = (key, pat)
    return pat


class ContactPattern(_FreeDofPattern):
    """A :class:`FreePattern` joined to the ``d x d`` blocks of node pairs a contact Hessian
    couples (any two surface nodes, outside the springs' pattern), on the free dofs.

    Kept for a run and rebuilt -- a new object, so the factorisation's symbolic analysis is
    redone only then -- when a contact Hessian couples a pair outside it (:func:`contact_values`).

    Attributes
    ----------
    base : FreePattern
    pairs : int64 array, the node pairs ``a n + b`` (both orders) joined to ``base``.
    base_slots : (base.nnz,) int64, the position of each ``base`` entry in this pattern's ``data``.
    extra : int64 array, the positions of the entries outside ``base``.
    extra_pairs : int64 array, the node pair ``a n + b`` of each of them.
    """

    def __init__(self, base: FreePattern, pairs: np.ndarray):
        from ...fem.sparsity import entry_pattern, structure_entries, union_structures

        d, free = base.dim, base.free
        n, nf = base.ndof // d, len(free)
        self.base, self.pairs = base, np.asarray(pairs, dtype=np.int64)
        renumber = np.full(base.ndof, -1, dtype=np.int64)
        renumber[free] = np.arange(nf)
        e, shape = np.arange(d), (len(self.pairs), d, d)
        # entry (p, q) of the block of pair (a, b): row a d + p, column b d + q
        rows = renumber[np.broadcast_to((self.pairs // n)[:, None, None] * d + e[:, None], shape)]
        cols = renumber[np.broadcast_to((self.pairs % n)[:, None, None] * d + e, shape)]
        rows, cols = rows.ravel(), cols.ravel()
        inside = (rows >= 0) & (cols >= 0)
        ip, ix, _ = entry_pattern(rows[inside], cols[inside], nf)
        indptr, indices, (self.base_slots, _) = union_structures(
            [(base.indptr, base.indices), (ip, ix)], nf)
        outside = np.ones(len(indices), dtype=bool)
        outside[self.base_slots] = False
        self.extra = np.flatnonzero(outside)
        r, c = structure_entries(indptr, indices)
        self.extra_pairs = free[r[self.extra]] // d * n + free[c[self.extra]] // d
        self.indptr, self.indices = indptr.astype(np.int32), indices.astype(np.int32)
        self.nnz = len(indices)
        self.coordinate_pair = _coordinate_pairs(free, self.indptr, self.indices, d)
        self.dim, self.free, self.shape, self.ndof = d, free, (nf, nf), base.ndof

    def values(self, base_data: np.ndarray, matrices, scale: float):
        """``data`` of ``base_data`` (on :attr:`base`) plus ``scale`` times the full
        ``ndof x ndof`` ``matrices`` (``None`` skipped) on the free dofs, or ``None`` when one of
        them has an entry outside this pattern."""
        data = np.zeros(self.nnz)
        data[self.base_slots] = base_data
        for B in matrices:
            if B is not None and not self.add(data, B, scale):
                return None
        return data


def node_pairs(matrices, n: int, d: int) -> np.ndarray:
    """The node pairs ``a n + b`` the entries of sparse ``nd x nd`` ``matrices`` couple (``None``
    skipped), unique."""
    keys = [np.zeros(0, dtype=np.int64)]
    for B in matrices:
        if B is not None:
            C = sp.coo_matrix(B)
            keys.append(C.row.astype(np.int64) // d * n + C.col.astype(np.int64) // d)
    return np.unique(np.concatenate(keys))


def contact_values(base: FreePattern, base_data: np.ndarray, matrices, scale: float,
                   cache: dict) -> tuple[ContactPattern, np.ndarray]:
    """``(pattern, data)``: ``base_data + scale * sum(matrices)`` (a contact Hessian's
    couplings) on the :class:`ContactPattern` kept in ``cache`` (a run's ``ctx.cache``).

    The kept pattern serves while every coupling fits; otherwise a new one is built from the
    couplings of ``matrices`` and those outside ``base`` that were nonzero since the last
    build (pairs that left contact since then are dropped, so the pattern follows the contact
    set instead of growing with every pair a run ever touched).
    """
    kept = cache.get("contact_pattern")
    pat, used = kept if kept is not None and kept[0].base is base else (None, None)
    data = None if pat is None else pat.values(base_data, matrices, scale)
    if data is None:
        n = base.ndof // base.dim
        pairs = node_pairs(matrices, n, base.dim)
        if pat is not None:
            pairs = np.union1d(pairs, pat.extra_pairs[used])
        pat = ContactPattern(base, pairs)
        used = np.zeros(len(pat.extra), dtype=bool)
        data = pat.values(base_data, matrices, scale)
    used |= data[pat.extra] != 0.0
    cache["contact_pattern"] = (pat, used)
    return pat, data


def assemble_with_forces(pat: FreePattern, system, x, v, t: float, *, diagonal, kcoef: float,
                         dcoef: float, fix: str | None, skip=()):
    """One implicit step's matrix and vectors, the springs in one compiled pass.

    Returns ``(data, f, kv)``: the values (on ``pat``) of
    ``diag(diagonal) + kcoef K_fix(x) + dcoef D(x)`` (``K``: springs with the definiteness fix
    and the declared forces' stiffness, e.g. contact; ``D``: dashpots and the declared forces'
    damping, e.g. viscous, not Rayleigh), the force ``system.force(x, v, t, rayleigh=False)``
    ``(n, d)`` and the product ``K_fix(x) v`` ``(n, d)`` -- the same three objects as
    ``stiffness_matrix`` / ``damping_matrix`` / ``force`` of the system
    (:class:`~femkit.dynamics.system.MassSpringSystem`), tested equal to them. The forces in
    ``skip`` are left out of all three (a contact force, whose Hessian the caller puts on a
    :class:`ContactPattern`).
    """
    from ...errors import SolverError
    from ..forces.rayleigh import RayleighDamping

    system._check_fix(fix)
    x = system._state(x)
    v = system._state(v, "v")
    clamp = fix == "clamp"
    data, f, kv = pat.assemble(system, x, diagonal=diagonal, kcoef=kcoef, ccoef=dcoef,
                               clamp=clamp, v=v, want_force=True, want_kv=True)
    force_fix = "clamp" if clamp else None
    moving = bool(v.any())
    for k, force in enumerate(system.forces):
        if any(force is f for f in skip):
            continue
        Kf = force.stiffness(x, force_fix)    # first: an elastic body's pass keeps its gradient
        if not isinstance(force, RayleighDamping):
            force.add_force(x, v, t, f)
        Df = force.damping(x)
        for B, coef, own in ((Kf, kcoef, k in pat.force_slots), (Df, dcoef, False)):
            if B is None:
                continue
            if own:  # the force's declared fixed structure: its values go straight to their slots
                entries, slots = pat.force_slots[k]
                if B.nnz != len(force.structure()[1]):
                    raise SolverError(f"{force!r}: its matrix left the structure it declared")
                data[slots] += coef * B.data[entries]
            elif not pat.add(data, B, coef):
                raise SolverError(f"{force!r}: its matrix has entries outside the nodal blocks "
                                  "of the compiled pattern")
        if Kf is not None and moving:
            kv += (Kf @ v.reshape(-1)).reshape(v.shape)
    if fix == "regularize":
        mu = system.regularization_shift(x)
        system.last_shift = mu
        data[pat.diag] += kcoef * mu
        kv += mu * v
    f[system.pinned_dofs] = 0.0
    return data, f, kv
