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

__all__ = ["FreePattern", "free_pattern"]


class FreePattern:
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
        coord = free % d
        rows = np.repeat(np.arange(nf), np.diff(self.indptr))
        self.coordinate_pair = (coord[rows] * d + coord[self.indices]).astype(np.int8)
        self.dim = d
        self.free = free
        self.shape = (nf, nf)
        self.ndof = system.ndof

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


def assemble_with_forces(pat: FreePattern, system, x, v, t: float, *, diagonal, kcoef: float,
                         dcoef: float, fix: str | None):
    """One implicit step's matrix and vectors, the springs in one compiled pass.

    Returns ``(data, f, kv)``: the values (on ``pat``) of
    ``diag(diagonal) + kcoef K_fix(x) + dcoef D(x)`` (``K``: springs with the definiteness fix
    and the declared forces' stiffness, e.g. contact; ``D``: dashpots and the declared forces'
    damping, e.g. viscous, not Rayleigh), the force ``system.force(x, v, t, rayleigh=False)``
    ``(n, d)`` and the product ``K_fix(x) v`` ``(n, d)`` -- the same three objects as
    ``stiffness_matrix`` / ``damping_matrix`` / ``force`` of the system
    (:class:`~femkit.dynamics.system.MassSpringSystem`), tested equal to them.
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
