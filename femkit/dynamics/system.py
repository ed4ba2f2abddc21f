"""The mass-spring system: particles, springs, declared forces, Jacobians and energies.

State arrays are node-major ``(n, d)`` float64 (``d`` = 2 or 3); the flat dof index is
``i*d + c`` (``x.reshape(-1)``). See the dynamics contract in ``docs/modules.md``.

Pinned nodes and components
---------------------------
``pinned`` holds whole nodes (indices or an ``(n,)`` mask) or single components (an ``(n, d)``
mask: rollers and symmetry planes, a node held in ``x`` only). ``pinned_dofs`` is the ``(n, d)``
mask of every held component, ``pinned`` the ``(n,)`` mask of the nodes held in every component,
``free_dofs`` the flat indices of the others. :meth:`MassSpringSystem.force`,
:meth:`~MassSpringSystem.acceleration` and :meth:`~MassSpringSystem.potential_gradient` are zero
on every held component (so explicit methods never move one); the implicit methods eliminate
them from their linear systems through ``free_dofs``. The matrices
(:meth:`~MassSpringSystem.stiffness_matrix`, :meth:`~MassSpringSystem.damping_matrix`,
:meth:`~MassSpringSystem.hessian_product`, :meth:`~MassSpringSystem.spring_laplacian`) are the
full, unconstrained Jacobians; an integrator restricts them to ``free_dofs``
(:meth:`~MassSpringSystem.free_block` does ``A[free][:, free]``).

Example: one spring stretched from rest length 1 to 2 pulls its ends together.

>>> import numpy as np
>>> s = MassSpringSystem(np.array([[0., 0.], [2., 0.]]), 1.0, [[0, 1]], k=3.0, rest=1.0)
>>> s.force(s.x0, s.v0).tolist()
[[3.0, 0.0], [-3.0, 0.0]]
>>> s.energies(s.x0, s.v0)["spring"]
1.5
"""

from __future__ import annotations

import copy
from typing import Callable, Iterable

import numpy as np
import scipy.sparse as sp

from ..errors import InputError, UnknownNameError
from .forces.base import Force
from .forces.elastic import ElasticForce
from .forces.rayleigh import RayleighDamping
from .forces.springs import dashpot_forces, geometry_from_difference, hooke_forces, spring_energy
from .forces.jacobian import (
    FIXES,
    _transverse_factor,
    SpringPattern,
    dashpot_blocks,
    regularization_shift,
    spring_block_product,
    spring_blocks,
)

__all__ = ["MassSpringSystem", "COMPILED_SPRINGS", "elastic_system"]

#: From this many springs on, :meth:`MassSpringSystem.spring_forces` (Hooke only) runs the
#: compiled one-pass kernel (:func:`femkit.dynamics.kernels.spring_kernels.spring_forces`)
#: instead of the two sparse products; below it the NumPy path avoids importing numba.
COMPILED_SPRINGS = 10_000


def _per_item(value, count: int, name: str, *, positive: bool = False) -> np.ndarray:
    a = np.asarray(value, dtype=float)
    if a.ndim == 0:
        a = np.full(count, float(a))
    if a.shape != (count,):
        raise InputError(f"{name} must be a scalar or have {count} entries, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} must be finite")
    if positive and np.any(a <= 0.0):
        bad = np.flatnonzero(a <= 0.0)[:5].tolist()
        raise InputError(f"{name} must be > 0 (offending entries {bad})")
    if not positive and np.any(a < 0.0):
        bad = np.flatnonzero(a < 0.0)[:5].tolist()
        raise InputError(f"{name} must be >= 0 (offending entries {bad})")
    return np.ascontiguousarray(a)


class MassSpringSystem:
    """Particles connected by Hooke springs (with optional dashpots) plus declared forces.

    Parameters
    ----------
    x0 : (n, d) array
        Initial positions, ``d`` = 2 or 3.
    mass : float or (n,) array
        Particle masses (> 0).
    springs : (s, 2) int array
        Spring end indices ``(i, j)``, ``i != j``.
    k : float or (s,) array
        Spring stiffnesses (>= 0).
    rest : float or (s,) array, optional
        Rest lengths; default the initial lengths ``|x0_j - x0_i|`` (which must be > 0).
    damping : float or (s,) array
        Dashpot coefficient along each spring; dashpots are evaluated only when non-zero.
    v0 : (n, d) array, optional
        Initial velocities (default zero; pinned rows are set to zero).
    pinned : index list, (n,) bool mask or (n, d) bool mask, optional
        Particles held fixed (every component), or with an ``(n, d)`` mask the components
        held fixed (the others move freely: a roller).
    forces : iterable of :class:`~femkit.dynamics.forces.base.Force`
        Declared extra forces (Gravity, ViscousDamping, RayleighDamping, GroundContact,
        SphereContact). Nothing undeclared is computed.
    family : (s,) int array, optional
        Spring family code per spring (see :mod:`femkit.dynamics.topology`), kept for output.

    Raises
    ------
    InputError
        Wrong shapes, non-finite values, masses <= 0, negative stiffness/rest/damping,
        out-of-range or self-connected springs, zero default rest length.
    """

    def __init__(self, x0, mass, springs, k, rest=None, damping=0.0, *, v0=None, pinned=None,
                 forces: Iterable[Force] = (), family=None):
        x0 = np.array(x0, dtype=float)
        if x0.ndim != 2 or x0.shape[1] not in (2, 3) or x0.shape[0] == 0:
            raise InputError(f"x0 must have shape (n, 2) or (n, 3) with n >= 1, got {x0.shape}")
        if not np.all(np.isfinite(x0)):
            raise InputError("x0 must be finite")
        n, d = x0.shape
        self.n, self.dim, self.ndof = n, d, n * d
        self.x0 = x0
        self.mass = _per_item(mass, n, "mass", positive=True)

        sp_arr = np.asarray(springs)
        if sp_arr.size == 0:
            sp_arr = np.zeros((0, 2), dtype=np.intp)
        if sp_arr.ndim != 2 or sp_arr.shape[1] != 2 or not np.issubdtype(sp_arr.dtype, np.integer):
            raise InputError(f"springs must be an (s, 2) integer array, got shape {sp_arr.shape}, dtype {sp_arr.dtype}")
        sp_arr = sp_arr.astype(np.intp)
        if sp_arr.size and (sp_arr.min() < 0 or sp_arr.max() >= n):
            raise InputError(f"spring indices must lie in [0, {n - 1}]")
        selfc = np.flatnonzero(sp_arr[:, 0] == sp_arr[:, 1])
        if len(selfc):
            raise InputError(f"springs connect a node to itself (springs {selfc[:5].tolist()})")
        self.springs = np.ascontiguousarray(sp_arr)
        s = len(sp_arr)
        self.n_springs = s
        self._i = np.ascontiguousarray(sp_arr[:, 0])
        self._j = np.ascontiguousarray(sp_arr[:, 1])
        self.k = _per_item(k, s, "spring stiffness k")
        if rest is None:
            d0 = np.take(x0, self._j, axis=0) - np.take(x0, self._i, axis=0)
            l0 = np.sqrt(np.einsum("sd,sd->s", d0, d0))
            zero = np.flatnonzero(l0 == 0.0)
            if len(zero):
                raise InputError(
                    f"springs {zero[:5].tolist()} have coincident endpoints in x0, so their default "
                    "rest length would be 0: give rest lengths explicitly or fix the positions")
            rest = l0
        self.rest = _per_item(rest, s, "spring rest length")
        self.damping = _per_item(damping, s, "spring damping")
        self._has_dashpots = bool(np.any(self.damping > 0.0))
        self.family = None if family is None else np.asarray(family)
        scale = max(float(self.rest.max()) if s else 0.0, float(np.ptp(x0, axis=0).max()), 1e-300)
        self.length_floor = 1e-12 * scale

        dofs = np.zeros((n, d), dtype=bool)
        if pinned is not None:
            p = np.asarray(pinned)
            if p.dtype == bool:
                if p.shape == (n,):
                    dofs[p] = True
                elif p.shape == (n, d):
                    dofs = p.copy()
                else:
                    raise InputError(f"pinned mask must have shape ({n},) (whole nodes) or "
                                     f"({n}, {d}) (components), got {p.shape}")
            elif p.size:
                if not np.issubdtype(p.dtype, np.integer):
                    raise InputError("pinned must be node indices or a boolean mask")
                if p.min() < -n or p.max() >= n:
                    raise InputError(f"pinned node indices must lie in [0, {n - 1}]")
                dofs[p.ravel()] = True
        self.pinned_dofs = dofs
        self.pinned = dofs.all(axis=1)
        self.free_dofs = np.flatnonzero(~dofs.ravel())

        if v0 is None:
            v = np.zeros_like(x0)
        else:
            v = np.array(v0, dtype=float)
            if v.shape != x0.shape or not np.all(np.isfinite(v)):
                raise InputError(f"v0 must be finite with shape {x0.shape}")
            v[dofs] = 0.0
        self.v0 = v

        # flat scatter indices: per-spring force on i goes to i*d + c, its negative to j*d + c
        c = np.arange(d)
        self._scatter = np.concatenate([(self._i[:, None] * d + c).ravel(),
                                        (self._j[:, None] * d + c).ravel()])
        self._pattern = None
        self._diff_ops = None
        self.last_shift = 0.0

        # each system binds its own shallow copies, so one force object may serve many systems
        self.forces = ()
        self.attach(*forces)

    def attach(self, *forces: Force) -> None:
        """Bind shallow copies of ``forces`` to this system and add them to :attr:`forces`
        (a force that needs the built system, e.g. barrier contact on its triangles)."""
        for f in forces:
            if not isinstance(f, Force):
                raise InputError(f"forces must be femkit force objects, got {f!r}")
        new = tuple(copy.copy(f) for f in forces)
        for f in new:
            f.bind(self)
        self.forces = self.forces + new
        self._rayleigh = tuple(f for f in self.forces if isinstance(f, RayleighDamping))
        self._conservative = tuple(f for f in self.forces if f.kind is not None)

    # ------------------------------------------------------------------ helpers
    def __repr__(self) -> str:
        return (f"MassSpringSystem(n={self.n}, dim={self.dim}, springs={self.n_springs}, "
                f"pinned={int(self.pinned.sum())}, forces={list(self.forces)})")

    @property
    def pattern(self) -> SpringPattern:
        """Sparsity pattern and scatter map of the spring matrices (built once, cached)."""
        if self._pattern is None:
            self._pattern = SpringPattern(self.n, self.dim, self._i, self._j)
        return self._pattern

    @property
    def partially_pinned(self) -> bool:
        """Whether some node is held in some components only (a roller)."""
        return bool(np.any(self.pinned_dofs.any(axis=1) & ~self.pinned))

    @property
    def rayleigh(self) -> tuple[float, float]:
        """``(alpha_mass, beta_stiffness)`` of the declared Rayleigh damping, ``(0, 0)`` if none."""
        return (float(sum(f.alpha for f in self._rayleigh)), float(sum(f.beta for f in self._rayleigh)))

    def _state(self, x, name="x") -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if x.shape != (self.n, self.dim):
            if x.shape == (self.ndof,):
                return x.reshape(self.n, self.dim)
            raise InputError(f"{name} must have shape ({self.n}, {self.dim}), got {x.shape}")
        return x

    @property
    def difference_operators(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """``(G, S)``: ``G`` (``s x n``, CSR) maps positions to spring vectors
        ``x_j - x_i``; ``S = -G^T`` (``n x s``) scatters per-spring values to end ``i`` (and
        their negatives to end ``j``). Built once per topology; applied to ``(n, d)`` arrays
        these are one sparse pass for all ``d`` coordinates (faster than ``np.take`` +
        ``np.bincount`` per coordinate on cloth-sized systems)."""
        if self._diff_ops is None:
            s = self.n_springs
            rows = np.concatenate([np.arange(s), np.arange(s)])
            cols = np.concatenate([self._j, self._i])
            vals = np.concatenate([np.ones(s), -np.ones(s)])
            G = sp.csr_matrix((vals, (rows, cols)), shape=(s, self.n))
            self._diff_ops = (G, (-G.T).tocsr())
        return self._diff_ops

    def _geometry(self, x):
        return geometry_from_difference(self.difference_operators[0] @ x, self.length_floor)

    def _scatter_springs(self, fs: np.ndarray) -> np.ndarray:
        """(s, d) per-spring values on end i (end j gets the negative) -> (n, d)."""
        if not self.n_springs:
            return np.zeros((self.n, self.dim))
        return self.difference_operators[1] @ fs

    def free_block(self, A):
        """``A[free][:, free]`` of an ``ndof x ndof`` matrix (pinned dofs removed)."""
        f = self.free_dofs
        return A[f][:, f]

    # ------------------------------------------------------------------ forces
    def spring_forces(self, x, v=None) -> np.ndarray:
        """Hooke (+ dashpot when ``v`` is given and damping is non-zero) forces, ``(n, d)``, pins not zeroed."""
        x = self._state(x)
        if (v is None or not self._has_dashpots) and self.n_springs >= COMPILED_SPRINGS:
            # Hooke only, one compiled pass over the springs (femkit.dynamics.kernels)
            from .kernels.spring_kernels import spring_forces

            out = np.zeros((self.n, self.dim))
            spring_forces(np.ascontiguousarray(x), self._i, self._j, self.k, self.rest,
                          self.length_floor, out)
            return out
        if (v is None or not self._has_dashpots) and self.n_springs:
            # Hooke only: f_i = k (l - L) / l (x_j - x_i), two sparse passes and no unit vectors
            dx = self.difference_operators[0] @ x
            l = np.sqrt(np.einsum("sd,sd->s", dx, dx))
            if l.min() >= self.length_floor:
                dx *= (self.k * (l - self.rest) / l)[:, None]
                return self.difference_operators[1] @ dx
        _, l, u = self._geometry(x)
        fs = hooke_forces(l, u, self.k, self.rest)
        if v is not None and self._has_dashpots:
            v = self._state(v, "v")
            fs += dashpot_forces(np.take(v, self._i, axis=0), np.take(v, self._j, axis=0), u, self.damping)
        return self._scatter_springs(fs)

    def force(self, x, v, t: float = 0.0, *, rayleigh: bool = True) -> np.ndarray:
        """Total force ``(n, d)``; zero on pinned components.

        ``rayleigh=False`` omits the Rayleigh term (for implicit methods that put
        ``alpha M + beta K`` into their matrix).
        """
        x = self._state(x)
        v = self._state(v, "v")
        out = self.spring_forces(x, v)
        for f in self.forces:
            if rayleigh or not isinstance(f, RayleighDamping):
                f.add_force(x, v, t, out)
        out[self.pinned_dofs] = 0.0
        return out

    def constant_force(self) -> np.ndarray:
        """Sum of the declared forces flagged ``constant`` (gravity), ``(n, d)``, zero on pins.

        ``force(x, v, t) == spring_forces(x) + constant_force() + variable_force(x, v, t)``
        (Hooke part unpinned-rows only), so a local/global solver can evaluate this once.
        """
        out = np.zeros((self.n, self.dim))
        zero = np.zeros_like(out)
        for f in self.forces:
            if f.constant:
                f.add_force(self.x0, zero, 0.0, out)
        out[self.pinned_dofs] = 0.0
        return out

    @property
    def has_variable_forces(self) -> bool:
        """Whether :meth:`variable_force` can be non-zero (dashpots or a non-constant force)."""
        return self._has_dashpots or any(not f.constant for f in self.forces)

    def variable_force(self, x, v, t: float = 0.0) -> np.ndarray:
        """Dashpots plus every declared force not flagged ``constant``, ``(n, d)``, zero on pins:
        :meth:`force` minus the Hooke springs and :meth:`constant_force`."""
        x = self._state(x)
        v = self._state(v, "v")
        if self._has_dashpots:
            _, _, u = self._geometry(x)
            out = self._scatter_springs(
                dashpot_forces(np.take(v, self._i, axis=0), np.take(v, self._j, axis=0), u, self.damping))
        else:
            out = np.zeros((self.n, self.dim))
        for f in self.forces:
            if not f.constant:
                f.add_force(x, v, t, out)
        out[self.pinned_dofs] = 0.0
        return out

    def acceleration(self, x, v, t: float = 0.0, *, rayleigh: bool = True) -> np.ndarray:
        """``force / mass``, zero on pinned components."""
        return self.force(x, v, t, rayleigh=rayleigh) / self.mass[:, None]

    def potential_gradient(self, x) -> np.ndarray:
        """Gradient of :meth:`potential_energy` = minus the conservative force (springs,
        gravity, contact); zero on pinned components."""
        x = self._state(x)
        out = self.spring_forces(x)
        zero_v = np.zeros_like(x)
        for f in self._conservative:
            f.add_force(x, zero_v, 0.0, out)
        out[self.pinned_dofs] = 0.0
        return -out

    # ------------------------------------------------------------------ energies
    def potential_energy(self, x) -> float:
        """Spring + gravity + contact energy."""
        e = self.energies(x, None)
        return e["spring"] + e["gravity"] + e["contact"]

    def energies(self, x, v) -> dict:
        """``dict(kinetic, spring, gravity, contact, total)`` (``v=None`` gives kinetic 0)."""
        x = self._state(x)
        if self.n_springs >= COMPILED_SPRINGS:  # one compiled pass, no (s, d) temporaries
            from .kernels.spring_kernels import spring_energy as compiled_energy

            spring = float(compiled_energy(np.ascontiguousarray(x), self._i, self._j, self.k,
                                           self.rest, self.length_floor))
        else:
            _, l, _ = self._geometry(x)
            spring = spring_energy(l, self.k, self.rest)
        out = {"kinetic": 0.0, "spring": spring, "gravity": 0.0, "contact": 0.0}
        if v is not None:
            v = self._state(v, "v")
            out["kinetic"] = float(0.5 * np.einsum("n,nd,nd->", self.mass, v, v))
        for f in self._conservative:
            out[f.kind] += f.energy(x)
        out["total"] = out["kinetic"] + out["spring"] + out["gravity"] + out["contact"]
        return out

    def momentum(self, v) -> np.ndarray:
        """Linear momentum ``sum_i m_i v_i``, shape ``(d,)``."""
        v = self._state(v, "v")
        return self.mass @ v

    # ------------------------------------------------------------------ matrices
    def _check_fix(self, fix):
        if fix not in FIXES:
            raise UnknownNameError("definiteness fix", str(fix), [f for f in FIXES if f])

    def regularization_shift(self, x) -> float:
        """The ``mu`` of ``fix="regularize"`` at ``x`` (see :func:`femkit.dynamics.forces.jacobian.regularization_shift`)."""
        x = self._state(x)
        _, l, _ = self._geometry(x)
        extra = None
        for f in self.forces:
            e = f.negative_bound(x)
            if e is not None:
                extra = e if extra is None else extra + e
        return regularization_shift(self.n, self._i, self._j, l, self.rest, self.k, extra)

    def stiffness_matrix(self, x, *, fix: str | None = None) -> sp.csr_matrix:
        """``K = -df/dx`` of springs and contacts (full, pins not removed), CSR ``ndof x ndof``.

        ``fix``: ``None``; ``"clamp"`` (per-spring/per-contact eigenvalue clamp, PSD result);
        ``"regularize"`` (``K + mu I`` with the analytic shift :meth:`regularization_shift`,
        stored in ``self.last_shift``). Dashpots' position derivative is not included.
        """
        self._check_fix(fix)
        x = self._state(x)
        _, l, u = self._geometry(x)
        H = spring_blocks(l, u, self.k, self.rest, "clamp" if fix == "clamp" else None)
        mu = self.regularization_shift(x) if fix == "regularize" else 0.0
        self.last_shift = mu
        K = self.pattern.assemble(H, mu if mu else None)
        for f in self.forces:
            Kf = f.stiffness(x, "clamp" if fix == "clamp" else None)
            if Kf is not None:
                K = K + Kf
        return K.tocsr()

    def hessian_product(self, x, d, *, fix: str | None = None) -> np.ndarray:
        """Matrix-free ``K d`` (matrix-free CG on the implicit-Euler matrix, Baraff & Witkin 1998:
        ``A d = M d + h^2 sum_j H_j d``), equal to
        ``stiffness_matrix(x, fix=fix) @ d`` with ``d`` of shape ``(n, d)`` or flat."""
        self._check_fix(fix)
        x = self._state(x)
        dd = self._state(d, "d")
        _, l, u = self._geometry(x)
        diff = np.take(dd, self._j, axis=0) - np.take(dd, self._i, axis=0)
        y = spring_block_product(l, u, self.k, self.rest, diff, "clamp" if fix == "clamp" else None)
        out = self._scatter_springs(-y)
        for f in self.forces:
            p = f.stiffness_product(x, dd, "clamp" if fix == "clamp" else None)
            if p is not None:
                out += p
        if fix == "regularize":
            out += self.regularization_shift(x) * dd
        return out

    def stiffness_operator(self, x, *, fix: str | None = None) -> Callable[[np.ndarray], np.ndarray]:
        """``d -> K d`` at a fixed ``x`` without assembling ``K``: the spring geometry and the
        per-spring coefficients are computed once, each product is two sparse passes over the
        springs (``G d``, scatter) plus the declared forces' own products. Equal to
        :meth:`hessian_product` ``(x, d, fix=fix)``; ``d`` flat or ``(n, d)``, result ``(n, d)``."""
        self._check_fix(fix)
        x = self._state(x)
        _, l, u = self._geometry(x)
        a = _transverse_factor(l, self.rest, "clamp" if fix == "clamp" else None)
        # signs folded in: the scatter S puts +y on end i, K d needs -H (d_j - d_i) there
        ka, kb = (-self.k * a)[:, None], -self.k * (1.0 - a)
        mu = self.regularization_shift(x) if fix == "regularize" else 0.0
        G, S = self.difference_operators if self.n_springs else (None, None)
        force_fix = "clamp" if fix == "clamp" else None
        buf = np.empty_like(u)

        def product(d):
            dd = self._state(d, "d")
            if self.n_springs:  # in place: one (s, d) temporary besides G d
                diff = G @ dd
                ud = np.einsum("sd,sd->s", u, diff)
                ud *= kb
                diff *= ka
                np.multiply(u, ud[:, None], out=buf)
                diff += buf
                out = S @ diff
            else:
                out = np.zeros((self.n, self.dim))
            for f in self.forces:
                p = f.stiffness_product(x, dd, force_fix)
                if p is not None:
                    out += p
            if mu:
                out += mu * dd
            return out

        return product

    def damping_operator(self, x) -> Callable[[np.ndarray], np.ndarray]:
        """``d -> D d`` at a fixed ``x`` without assembling the spring-pattern matrix ``D``
        (dashpots ``c u u^T`` per spring, computed once; nodal forces such as viscous damping
        through their diagonal ``D``). Equal to ``damping_matrix(x) @ d``; result ``(n, d)``."""
        x = self._state(x)
        if self._has_dashpots:
            _, _, u = self._geometry(x)
            G, S = self.difference_operators
            c = self.damping
        nodal = [D for D in (f.damping(x) for f in self.forces) if D is not None]

        def product(d):
            dd = self._state(d, "d")
            if self._has_dashpots:
                diff = G @ dd
                out = S @ (-(c * np.einsum("sd,sd->s", u, diff))[:, None] * u)
            else:
                out = np.zeros((self.n, self.dim))
            for D in nodal:
                out += (D @ dd.reshape(-1)).reshape(self.n, self.dim)
            return out

        return product

    def damping_product(self, x, d) -> np.ndarray:
        """Matrix-free ``D d`` (dashpots + viscous, not Rayleigh), equal to
        ``damping_matrix(x) @ d``; ``d`` flat or ``(n, d)``, result ``(n, d)``."""
        return self.damping_operator(x)(d)

    def _spring_diagonal(self, per_spring: np.ndarray) -> np.ndarray:
        """Flat ``(ndof,)`` diagonal from the ``(s, d)`` diagonals of the spring blocks (each
        block enters the ``(i, i)`` and ``(j, j)`` blocks with a plus sign)."""
        if not self.n_springs:
            return np.zeros(self.ndof)
        w = per_spring.ravel()
        return np.bincount(self._scatter, weights=np.concatenate([w, w]), minlength=self.ndof)

    def stiffness_diagonal(self, x, fix: str | None = None) -> np.ndarray:
        """Diagonal of ``stiffness_matrix(x, fix=fix)``, flat ``(ndof,)``, without assembling
        it: ``k (a + (1 - a) u_c^2)`` per spring and coordinate (``a = 1 - L/l``, clamped for
        ``fix="clamp"``) scattered to both ends with one ``np.bincount``, plus the declared
        forces' (contact) diagonals and the shift of ``fix="regularize"``. For a Jacobi
        preconditioner of matrix-free solves.

        >>> s = MassSpringSystem(np.array([[0., 0.], [2., 0.]]), 1.0, [[0, 1]], k=3.0, rest=1.0)
        >>> s.stiffness_diagonal(s.x0).tolist()      # along u: k = 3; across: k (1 - 1/2)
        [3.0, 1.5, 3.0, 1.5]
        """
        self._check_fix(fix)
        x = self._state(x)
        _, l, u = self._geometry(x)
        a = _transverse_factor(l, self.rest, "clamp" if fix == "clamp" else None)
        diag = self._spring_diagonal((self.k * a)[:, None] + (self.k * (1.0 - a))[:, None] * u * u)
        for f in self.forces:
            Kf = f.stiffness(x, "clamp" if fix == "clamp" else None)
            if Kf is not None:
                diag += Kf.diagonal()
        if fix == "regularize":
            diag += self.regularization_shift(x)
        return diag

    def damping_diagonal(self, x) -> np.ndarray:
        """Diagonal of :meth:`damping_matrix`, flat ``(ndof,)``, without assembling it."""
        x = self._state(x)
        if self._has_dashpots:
            _, _, u = self._geometry(x)
            diag = self._spring_diagonal(self.damping[:, None] * u * u)
        else:
            diag = np.zeros(self.ndof)
        for f in self.forces:
            Df = f.damping(x)
            if Df is not None:
                diag += Df.diagonal()
        return diag

    def damping_matrix(self, x) -> sp.csr_matrix:
        """``D = -df/dv`` of the dashpots (``c u u^T`` blocks) and viscous damping (not Rayleigh)."""
        x = self._state(x)
        if self._has_dashpots:
            _, _, u = self._geometry(x)
            D = self.pattern.assemble(dashpot_blocks(u, self.damping))
        else:
            D = sp.csr_matrix((self.ndof, self.ndof))
        for f in self.forces:
            Df = f.damping(x)
            if Df is not None:
                D = D + Df
        return D.tocsr()

    def mass_matrix(self) -> sp.csr_matrix:
        """Lumped mass matrix: masses repeated ``d`` times on the diagonal."""
        return sp.diags(np.repeat(self.mass, self.dim), format="csr")

    def spring_laplacian(self) -> sp.csr_matrix:
        """``L = sum_s k_s A_s A_s^T`` (``n x n``, Liu et al. 2013), ``A_s = e_i - e_j``.

        Liu's global step is ``(M_n + h^2 L) x = M_n y + h^2 J d`` per coordinate, with
        :meth:`spring_J` and :meth:`spring_directions`; pins are handled by the integrator.
        """
        pat = SpringPattern(self.n, 1, self._i, self._j)
        return pat.assemble(self.k.reshape(-1, 1, 1))

    def spring_J(self) -> sp.csr_matrix:
        """``J = sum_s k_s A_s S_s^T`` (``n x s``): ``J[i, s] = k_s``, ``J[j, s] = -k_s``."""
        s = self.n_springs
        cols = np.concatenate([np.arange(s), np.arange(s)])
        rows = np.concatenate([self._i, self._j])
        return sp.csr_matrix((np.concatenate([self.k, -self.k]), (rows, cols)), shape=(self.n, s))

    def spring_directions(self, x) -> np.ndarray:
        """Liu's local step: ``d_s = L_s (x_i - x_j) / |x_i - x_j|``, shape ``(s, d)``
        (the minimiser of ``|(x_i - x_j) - d|`` over ``|d| = L_s``)."""
        x = self._state(x)
        _, _, u = self._geometry(x)
        return -self.rest[:, None] * u

    def omega_max(self, x=None, **options) -> float:
        """Largest angular frequency of the linearisation at ``x`` (see :mod:`.stability`)."""
        from .stability import estimate_omega_max

        return estimate_omega_max(self, x, **options)


def elastic_system(body, *, x0=None, v0=None, pinned=None, forces: Iterable[Force] = ()):
    """A :class:`MassSpringSystem` whose only internal force is the
    elastic ``body`` (no springs), lumped masses from its density, plus the declared ``forces``
    (gravity, damping, contact) and ``pinned`` nodes; starts at rest positions unless ``x0``.

    >>> from femkit.solids import ElasticBody, StableNeoHookean
    >>> body = ElasticBody([[0., 0.], [1., 0.], [0., 1.]], [[0, 1, 2]], StableNeoHookean(1., 1.))
    >>> s = elastic_system(body, pinned=[0])
    >>> s.force(s.x0, s.v0).tolist()
    [[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]
    """
    x = body.rest_positions if x0 is None else np.asarray(x0, dtype=float)
    if x.shape != body.rest_positions.shape:
        raise InputError(f"x0 must have the body's shape {body.rest_positions.shape} "
                         f"({body.n} nodes), got {x.shape}")
    return MassSpringSystem(x, body.lumped_masses(), np.zeros((0, 2), dtype=np.int64), 0.0,
                            v0=v0, pinned=pinned, forces=[ElasticForce(body), *forces])
