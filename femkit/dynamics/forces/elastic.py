"""An elastic finite-element body as a force of femkit's dynamics system.

:class:`ElasticForce` wraps a :class:`femkit.solids.ElasticBody`: force ``-dE/dx``, energy
``E(x)`` (reported in the system's ``"spring"`` bucket, the elastic potential of a scene),
stiffness ``K = d^2E/dx^2`` (element-wise PSD-projected for the integrators' ``fix="clamp"``,
Teran et al. 2005) and, for ``fix="regularize"``, the per-node bound of the negative part of
``K`` (:meth:`~femkit.solids.ElasticBody.negative_bound`). So every registered integrator runs an
elastic solid unchanged, with the system's pinning, gravity, damping and contact.

:func:`femkit.dynamics.system.elastic_system` builds that system: lumped masses from the density
(:meth:`~femkit.solids.ElasticBody.lumped_masses`), no springs.

The last evaluation is kept (positions and result), because an implicit step asks for the
force, the energy and the stiffness at the same positions.
"""

from __future__ import annotations

import numpy as np

from .base import Force

__all__ = ["ElasticForce", "DeadLoad"]


class ElasticForce(Force):
    """The elastic force of a finite-element body (see module docstring).

    Parameters
    ----------
    body : femkit.solids.ElasticBody
        Its nodes are the system's particles, in the same order.
    """

    kind = "spring"

    def __init__(self, body):
        self.body = body
        self._kept = None

    def bind(self, system) -> None:
        from ...errors import InputError

        super().bind(system)
        if (system.n, system.dim) != (self.body.n, self.body.dim):
            raise InputError(f"elastic body has {self.body.n} nodes in {self.body.dim}D, the "
                             f"system {system.n} in {system.dim}D")
        self._kept = None

    def _eval(self, x, level: int, project: bool = False):
        kept = self._kept
        # energy and gradient do not depend on the projection, only the Hessian does
        if kept is not None and kept[1] >= level and (level < 2 or kept[2] == project) \
                and np.array_equal(kept[0], x):
            return kept[3]
        out = self.body.evaluate(x, level, project=project)
        self._kept = (np.array(x, copy=True), level, project, out)
        return out

    def add_force(self, x, v, t, out) -> None:
        out -= self._eval(x, 1)[1]

    def energy(self, x) -> float:
        return float(self._eval(x, 0)[0].sum())

    def stiffness(self, x, fix=None):
        return self._eval(x, 2, fix == "clamp")[2]

    @property
    def stored_scale(self) -> float:
        """``sum (mu + |lam|) vol``: the size of the terms the energy sums before they cancel
        near rest (the round-off level of the energy is ``eps`` times it)."""
        return float(sum((m.mu + abs(m.lam)) * self.body.rest.volumes[e].sum()
                         for e, m in self.body.groups))

    def structure(self):
        pat = self.body.pattern
        return pat.indptr, pat.indices

    def stiffness_product(self, x, d, fix=None):
        K = self.stiffness(x, fix)
        return (K @ np.asarray(d, dtype=float).reshape(-1)).reshape(self.body.n, self.body.dim)

    def negative_bound(self, x):
        return self.body.negative_bound(x)

    def __repr__(self) -> str:
        mats = ", ".join(m.name for m in self.body.materials)
        return f"ElasticForce({self.body.rest.n_cells} elements, {mats})"


class DeadLoad(Force):
    """Constant nodal forces ``f`` ``(n, d)`` (surface tractions of a solid as dead loads,
    :func:`femkit.solids.traction_forces`); potential ``-f . x`` over the unpinned components,
    reported in the ``"gravity"`` bucket (the bucket of constant external forces).

    >>> import numpy as np
    >>> from femkit.dynamics.system import MassSpringSystem
    >>> s = MassSpringSystem(np.zeros((2, 2)), 1.0, np.zeros((0, 2), int), 0.0, pinned=[0],
    ...                      forces=[DeadLoad([[1., 0.], [0., -2.]])])
    >>> s.force(s.x0, s.v0).tolist()
    [[0.0, 0.0], [0.0, -2.0]]
    """

    kind = "gravity"
    constant = True

    def __init__(self, forces):
        self.forces = np.asarray(forces, dtype=float)

    def bind(self, system) -> None:
        from ...errors import InputError

        super().bind(system)
        if self.forces.shape != (system.n, system.dim) or not np.all(np.isfinite(self.forces)):
            raise InputError(f"dead load must be finite with shape ({system.n}, {system.dim}), "
                             f"got {self.forces.shape}")
        self._f = np.where(system.pinned_dofs, 0.0, self.forces)

    def add_force(self, x, v, t, out) -> None:
        out += self._f

    def energy(self, x) -> float:
        return float(-np.einsum("nd,nd->", self._f, x))

    def __repr__(self) -> str:
        return f"DeadLoad({len(self.forces)} nodes)"
