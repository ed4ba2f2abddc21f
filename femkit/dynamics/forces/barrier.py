"""Barrier contact (IPC) as a force of femkit's dynamics: :class:`BarrierContact`.

The force wraps a :class:`femkit.contact.barrier.BarrierModel` (the log barrier, CCD, adaptive
stiffness and lagged friction through ipctk, the extra ``femkit[contact]``): energy
``kappa sum b(d_k)`` in the ``"contact"`` bucket, force minus its gradient, stiffness its
Hessian (each collision's block PSD-projected for ``fix="clamp"``). Unlike the penalty contacts
of :mod:`.contact`, which let bodies penetrate by design, it keeps every surface apart -- but
only under an integrator that minimises the step's incremental potential with every line-search
step bounded by :meth:`step_bound` (the collision-free step size): those declare
``Integrator.keeps_contact = True`` (``newton``), and every other integrator refuses a system
with this force when the run starts (:attr:`requires_bounded_steps`).

The step protocol the ``newton`` integrator calls (no-ops on every other force,
:class:`~.base.Force`): :meth:`begin_step` (the stiffness initialised on the first step, IPC's
rule; friction lagged at ``x_n``; moving obstacles started), :meth:`step_bound`,
:meth:`end_iteration` (IPC's stiffness update), :meth:`advance` (moving obstacles moved on,
the bodies touching one carried along in the integrator's iterate: solve again), :meth:`relag` (another friction lagging iteration) and :meth:`end_step`.
"""

from __future__ import annotations

import numpy as np

from .base import Force

__all__ = ["BarrierContact"]


class BarrierContact(Force):
    """IPC barrier contact of a system's surface (see module docstring).

    Parameters
    ----------
    surface : (k, 3) or (k, 2) int array
        The contact surface in the system's node numbering
        (:func:`femkit.contact.body_surface`).
    obstacles : sequence of :class:`femkit.contact.Obstacle`
    **options
        :class:`~femkit.contact.barrier.BarrierModel`'s keywords: ``dhat``, ``stiffness``,
        ``self_contact``, ``mu``, ``eps_v``, ``lagging``, ``ccd``.
    """

    kind = "contact"
    requires_bounded_steps = True

    def __init__(self, surface, obstacles=(), **options):
        self.surface = np.asarray(surface, dtype=np.int64)
        self.obstacles = tuple(obstacles)
        self.options = dict(options)
        self.model = None

    def bind(self, system) -> None:
        from ...contact.barrier import BarrierModel

        super().bind(system)
        self.model = BarrierModel(system.x0, self.surface, self.obstacles, **self.options)
        self._mask = ~system.pinned_dofs
        self._lags_left = 0
        self._pieces = None

    def add_force(self, x, v, t, out) -> None:
        out -= self.model.gradient(x) * self._mask

    def energy(self, x) -> float:
        return self.model.energy(x)

    def stiffness(self, x, fix=None):
        return self.model.hessian(x, project=fix == "clamp")

    def stiffness_product(self, x, d, fix=None):
        K = self.stiffness(x, fix)
        return (K @ np.asarray(d, float).reshape(-1)).reshape(x.shape)

    # ------------------------------------------------------------------ the step protocol
    def begin_step(self, x, h: float, objective_gradient, t: float = 0.0) -> None:
        """Start a step from ``x`` at time ``t`` of length ``h``: moving obstacles at their
        time-``t`` place and moved towards their step's end place as far as CCD allows; on the
        first step IPC's initial stiffness from ``objective_gradient(x)`` (the step objective's
        gradient without contact, flat), then friction frozen at ``x``."""
        m = self.model
        m.start_motion(t, h)
        m.advance(x)
        if m.kappa is None:
            m.init_stiffness(objective_gradient(x.reshape(-1)), float(np.mean(self._system.mass)),
                             h * h, x)
        m.lag_friction(x, x, h)
        self._lags_left = m.lagging - 1 if m.friction is not None else 0

    def step_bound(self, x, x_try) -> float:
        """The collision-free fraction of the move ``x -> x_try`` (flat or ``(n, d)``)."""
        return self.model.max_step(x, x_try)

    def end_iteration(self, x) -> bool:
        """IPC's stiffness update after an iteration; True when the objective changed."""
        return self.model.update_stiffness(x)

    def advance(self, x) -> bool:
        """Moving obstacles moved on towards their step's end place (CCD-bounded, the bodies at
        ``x``), the bodies' pieces touching one carried along with it when that goes farther
        (``x``, the integrator's iterate ``(n, d)``, written in place; pinned pieces never);
        True when they moved."""
        return self.model.advance(x, self.pieces())

    def pieces(self) -> np.ndarray:
        """The connected piece of every node (springs and the other forces' stiffness
        couplings at the rest place), ``-1`` on a piece with a pinned dof; computed once."""
        if self._pieces is None:
            import scipy.sparse as sp
            from scipy.sparse.csgraph import connected_components

            s = self._system
            rows, cols = [s._i], [s._j]
            for f in s.forces:
                K = None if f is self else f.stiffness(s.x0)
                if K is not None:
                    K = sp.coo_matrix(K)
                    rows.append(K.row // s.dim)
                    cols.append(K.col // s.dim)
            r, c = np.concatenate(rows), np.concatenate(cols)
            graph = sp.coo_matrix((np.ones(len(r)), (r, c)), shape=(s.n, s.n))
            pieces = connected_components(graph, directed=False)[1]
            held = np.unique(pieces[(~self._mask).reshape(s.n, -1).any(axis=1)])
            self._pieces = np.where(np.isin(pieces, held), -1, pieces)
        return self._pieces

    def relag(self, x_start, x, h: float) -> bool:
        """Another lagging iteration: friction re-frozen at the step's solution ``x``; False
        when the step's lagging iterations are spent (or there is no friction)."""
        if self._lags_left <= 0:
            return False
        self._lags_left -= 1
        self.model.lag_friction(x_start, x, h)
        return True

    def end_step(self) -> None:
        self.model.end_step()

    def __repr__(self) -> str:
        return f"BarrierContact({len(self.surface)} surface elements, {len(self.obstacles)} obstacles)"
