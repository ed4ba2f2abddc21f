"""The IPC log barrier, its continuous collision detection and smooth lagged friction, by ipctk.

Li et al. 2020 ("Incremental Potential Contact: intersection- and inversion-free,
large-deformation dynamics", ACM TOG 39(4)): the contact potential is
``kappa * sum_k b(d_k)`` over the pairs of surface primitives closer than ``dhat``, with the
clamped log barrier ``b(d) = -(d - dhat)^2 log(d / dhat)`` (ipctk's ``BarrierPotential``), which
grows without bound as a distance goes to 0. A minimiser that starts intersection-free and
never steps past the collision-free step size of continuous collision detection (ipctk's
``compute_collision_free_stepsize``, Tight-Inclusion CCD) therefore never lets two surfaces
touch: the guarantee of :class:`BarrierModel`'s users, the ``newton`` integrator and the static
solver. ``kappa`` adapts (IPC's rules, ipctk's ``initial_barrier_stiffness`` and
``update_barrier_stiffness``) unless given. Friction is IPC's smooth lagged Coulomb friction
(ipctk's ``TangentialCollisions`` and ``FrictionPotential``): the normal forces and tangent bases
are frozen ("lagged") at the start of a step, the friction force is ``-grad_v D(v)`` with
``v = (x - x_n) / h`` and ``D`` mollified below the slip speed ``eps_v``; as a potential of
``x`` it is ``h D((x - x_n) / h)``, whose gradient is that force (IPC's dissipative potential).

femkit's conventions: positions are node-major ``(n, d)``, the flat dof ``i*d + c``; the
potential's gradient is ``(n, d)`` on every node of the body (zero off its surface), its Hessian a
CSR matrix ``n d x n d``. Obstacles are part of the collision mesh but carry no dofs; a moving one
(a prescribed rigid motion: velocity or keyframed path, and rotation, :class:`~.surfaces.Motion`)
is moved within each step towards its place at the step's end in straight moves each bounded by
CCD against the bodies where the last solve left them (:meth:`BarrierModel.advance`; the step is
solved again after every move), so it never passes through a body; the bodies' pieces touching
it are carried along with its rigid move in the same CCD-bounded move when that goes farther (a
few moves a step instead of one per fraction of ``dhat``); friction sees each obstacle vertex's
own velocity over the step.

ipctk is the optional extra ``femkit[contact]`` (``pip install femkit[contact]``): importing this
module never needs it; building a :class:`BarrierModel` without it is a one-line
:class:`~femkit.errors.InputError`.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from .surfaces import Obstacle

__all__ = ["BarrierModel", "require_ipctk", "DHAT_SCALE", "REPORT_SCALE"]

#: ``dhat`` by default: this fraction of the bodies' bounding-box diagonal (IPC's 1e-3).
DHAT_SCALE = 1e-3
#: Minimum distances are reported up to this many ``dhat`` (farther: ``None``).
REPORT_SCALE = 10.0
#: The narrow-phase CCD methods (``BarrierModel(ccd=...)``, ``contact.ccd``).
CCD_METHODS = ("tight_inclusion", "additive")
#: Moves of a moving obstacle within one step, each bounded by CCD with the bodies where the
#: last solve left them (:meth:`BarrierModel.advance`).
MAX_ADVANCES = 200
#: ... and fewer when this many moves together gained under 1% of the way left: stuck.
STALL_MOVES = 20
#: Tight-Inclusion CCD's iteration cap per primitive pair (ipctk's default, 1e7, let one nearly
#: parallel face pair at a tiny gap -- a cube resting on a cube -- cost tens of seconds; at the
#: cap the root finder returns its conservative lower bound, so the guarantee stands).
CCD_MAX_ITERATIONS = 10_000


def require_ipctk():
    """The ipctk module, or a one-line InputError naming the extra to install."""
    try:
        import ipctk
    except ImportError:
        raise InputError("barrier contact needs ipctk: pip install femkit[contact] "
                         "(or pip install 'ipctk>=1.6')") from None
    return ipctk


def _positive(value, name: str) -> float:
    v = float(value)
    if not (np.isfinite(v) and v > 0.0):
        raise InputError(f"contact.{name} must be > 0, got {value!r}")
    return v


class BarrierModel:
    """Barrier contact of one set of bodies (their surfaces) and obstacles, static or in a
    prescribed rigid motion.

    ``seconds`` sums the time of the broad phase, CCD and the Hessians by :attr:`clock`
    (wall time; a benchmark may set CPU time).

    Parameters
    ----------
    x0 : (n, d) array
        The nodes of the bodies (all of them; only the surface's take part).
    surface : (k, 3) triangles or (k, 2) segments
        The bodies' contact surface in node numbering (:func:`~.surfaces.body_surface`).
    obstacles : sequence of Obstacle
    dhat : float, optional
        Activation distance; default :data:`DHAT_SCALE` times the bounding-box diagonal of ``x0``.
    stiffness : float, optional
        A fixed barrier stiffness ``kappa`` (energy units); default adaptive (IPC).
    self_contact : bool
        Whether a connected piece of the surface may touch itself (cloth folding, a bent bar);
        pieces always touch each other and the obstacles.
    mu : float
        Coulomb friction coefficient (0: frictionless).
    eps_v : float
        Friction's slip-speed mollifier (velocity units); below it friction is a stiff
        viscous law.
    lagging : int
        Friction lagging iterations per step (normal forces and tangent bases re-frozen at the
        step's solution and the step solved again, ``lagging - 1`` times).
    ccd : {"tight_inclusion", "additive"}
        The narrow-phase CCD: Tight-Inclusion (Wang et al. 2021, "A large-scale benchmark and an
        inclusion-based algorithm for continuous collision detection", ACM TOG 40(5):
        conservative including floating-point rounding; the default) or additive CCD (Li et al.
        2021, "Codimensional incremental potential contact", ACM TOG 40(4): conservative by
        construction, cheaper, not certified against rounding).

    Raises
    ------
    InputError
        ``dhat``, ``stiffness`` or ``eps_v`` not > 0, ``mu < 0``, ``lagging < 1``, an unknown
        ``ccd``, ipctk missing.
    """

    clock = staticmethod(time.perf_counter)

    def __init__(self, x0, surface, obstacles=(), *, dhat=None, stiffness=None,
                 self_contact: bool = True, mu: float = 0.0, eps_v: float = 1e-3,
                 lagging: int = 1, ccd: str = "tight_inclusion"):
        ipctk = require_ipctk()
        self._ipc = ipctk
        x0 = np.asarray(x0, dtype=float)
        self.n, self.dim = x0.shape
        self.length = float(np.linalg.norm(np.ptp(x0, axis=0))) or 1.0
        self.dhat = DHAT_SCALE * self.length if dhat is None else _positive(dhat, "dhat")
        self.fixed_stiffness = None if stiffness is None else _positive(stiffness, "stiffness")
        if not (np.isfinite(float(mu)) and float(mu) >= 0.0):
            raise InputError(f"contact.friction must be >= 0, got {mu!r}")
        self.mu, self.eps_v = float(mu), _positive(eps_v, "eps_v")
        if int(lagging) < 1:
            raise InputError(f"contact.lagging must be >= 1, got {lagging!r}")
        self.lagging = int(lagging)
        self.self_contact = bool(self_contact)
        surface = np.asarray(surface, dtype=np.int64)
        self.surface_nodes, local = np.unique(surface, return_inverse=True)
        self.nb = len(self.surface_nodes)
        faces = [local.reshape(surface.shape)]
        verts, offset = [np.zeros((0, self.dim))], self.nb
        #: each obstacle's rows of :attr:`static`
        self._rows = np.cumsum([0] + [len(ob.vertices) for ob in obstacles])
        for ob in obstacles:
            if ob.dim != self.dim:
                raise InputError(f"contact.obstacles: {ob.name} is {ob.dim}-D, the bodies "
                                 f"{self.dim}-D")
            verts.append(np.asarray(ob.vertices, float))
            faces.append(np.asarray(ob.faces, np.int64) + offset)
            offset += len(ob.vertices)
        self.obstacles = tuple(obstacles)
        self.static = np.concatenate(verts)      # the obstacles' vertices now
        self.static0 = self.static.copy()        # ... at time 0
        #: the obstacles' vertex velocities over the current step (friction's)
        self.static_velocity = np.zeros_like(self.static)
        self.moving = any(ob.moving for ob in obstacles)
        self._target = None                      # the obstacles' vertices at the step's end
        self.advances = 0                        # obstacle moves of the step
        self._left = []                          # the way left before each move of the step
        self.faces = np.ascontiguousarray(np.concatenate(faces), dtype=np.int32)
        self.n_obstacle_faces = len(self.faces) - len(surface)
        self.component = self._components()
        self.mesh = self._collision_mesh(x0)
        self.barrier = ipctk.BarrierPotential(self.dhat, 1.0)
        self.ccd_method = ccd
        if ccd not in CCD_METHODS:
            raise InputError(f"contact.ccd must be one of {', '.join(CCD_METHODS)}, got {ccd!r}")
        self.ccd = ipctk.TightInclusionCCD(1e-6, CCD_MAX_ITERATIONS) \
            if ccd == "tight_inclusion" else ipctk.AdditiveCCD()
        self.kappa = self.fixed_stiffness
        self.kappa_max = np.inf
        self.friction = ipctk.FrictionPotential(self.eps_v) if self.mu > 0 else None
        self._lag = None            # (x_n flat, h, TangentialCollisions) inside a step
        self._kept = (None, None)   # (collision vertices, NormalCollisions)
        self._sweep = None          # (lower, upper swept boxes, Candidates) of the last CCD move
        self.stats = {"collision_builds": 0, "ccd_calls": 0, "hessians": 0, "obstacle_moves": 0,
                      "carries": 0}
        self.seconds = {"broad_phase": 0.0, "ccd": 0.0, "hessian": 0.0}

    # ------------------------------------------------------------------ the collision mesh
    def _components(self) -> np.ndarray:
        """Connected piece of every collision vertex (obstacles included)."""
        from scipy.sparse.csgraph import connected_components

        m = self.nb + len(self.static)
        f = self.faces.astype(np.int64)
        rows = np.repeat(f[:, 0], f.shape[1] - 1)
        cols = f[:, 1:].ravel()
        graph = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(m, m))
        return connected_components(graph, directed=False)[1]

    def _collision_mesh(self, x0):
        ipc = self._ipc
        V = self.vertices(x0)
        if self.dim == 3:
            mesh = ipc.CollisionMesh(V, ipc.edges(self.faces), self.faces)
        else:
            mesh = ipc.CollisionMesh(V, self.faces)
        allowed = ipc.make_static_obstacle_filter(self.nb)
        if not self.self_contact:
            if self.dim == 3:
                allowed = allowed & ipc.make_connected_components_filter(self.faces)
            else:
                comp = self.component
                allowed = allowed & ipc.CollisionFilter(lambda i, j: bool(comp[i] != comp[j]))
        mesh.can_collide = allowed
        return mesh

    def vertices(self, x) -> np.ndarray:
        """The collision mesh's vertices: the surface nodes of ``x`` then the obstacles'."""
        x = np.asarray(x, dtype=float).reshape(self.n, self.dim)
        return np.asfortranarray(np.concatenate([x[self.surface_nodes], self.static]))

    def _collisions(self, x, dhat=None):
        V = self.vertices(x)
        if dhat is None and self._kept[0] is not None and np.array_equal(self._kept[0], V):
            return V, self._kept[1]
        t0 = self.clock()
        c = self._ipc.NormalCollisions()
        if dhat is None and self._within_sweep(V):
            cand = self._sweep[2]
        else:  # the same kind of broad phase at V: one collision set whichever way it is built
            cand = self._ipc.Candidates()
            cand.build(self.mesh, V, self.dhat if dhat is None else dhat)
        c.build(cand, self.mesh, V, self.dhat if dhat is None else dhat)
        self.seconds["broad_phase"] += self.clock() - t0
        self.stats["collision_builds"] += 1
        if dhat is None:
            self._kept = (V, c)
        return V, c

    # ------------------------------------------------------------------ dofs
    def _to_nodes(self, g_flat) -> np.ndarray:
        out = np.zeros((self.n, self.dim))
        out[self.surface_nodes] = np.asarray(g_flat).reshape(-1, self.dim)[:self.nb]
        return out

    def _to_dofs(self, H) -> sp.csr_matrix:
        d, nbd = self.dim, self.nb * self.dim
        H = sp.coo_matrix(H)
        keep = (H.row < nbd) & (H.col < nbd)
        dof = (self.surface_nodes[:, None] * d + np.arange(d)).ravel()
        return sp.csr_matrix((H.data[keep], (dof[H.row[keep]], dof[H.col[keep]])),
                             shape=(self.n * d, self.n * d))

    # ------------------------------------------------------------------ the barrier
    @property
    def kappa_value(self) -> float:
        """The barrier stiffness now (0 before it is initialised)."""
        return 0.0 if self.kappa is None else float(self.kappa)

    def energy(self, x) -> float:
        """``kappa * sum b(d_k)`` (+ the lagged friction potential inside a step)."""
        V, c = self._collisions(x)
        e = self.kappa_value * float(self.barrier(c, self.mesh, V)) if len(c) else 0.0
        return e + self._friction_energy(x)

    def barrier_gradient(self, x) -> np.ndarray:
        """Gradient ``(n, d)`` of the unit-stiffness barrier ``sum b(d_k)``."""
        V, c = self._collisions(x)
        if not len(c):
            return np.zeros((self.n, self.dim))
        return self._to_nodes(self.barrier.gradient(c, self.mesh, V))

    def gradient(self, x) -> np.ndarray:
        """Gradient ``(n, d)`` of :meth:`energy` (minus the contact force)."""
        g = self.kappa_value * self.barrier_gradient(x) if self.kappa else \
            np.zeros((self.n, self.dim))
        return g + self._friction_gradient(x)

    def hessian(self, x, project: bool = True) -> sp.csr_matrix:
        """Hessian of :meth:`energy`, CSR ``n d x n d``; ``project``: each collision's block
        projected onto its positive semi-definite part (ipctk's clamp)."""
        t0 = self.clock()
        V, c = self._collisions(x)
        how = self._ipc.PSDProjectionMethod.CLAMP if project else \
            self._ipc.PSDProjectionMethod.NONE
        H = None
        if len(c) and self.kappa:
            H = self.kappa_value * self._to_dofs(self.barrier.hessian(c, self.mesh, V, how))
        F = self._friction_hessian(x, how)
        if F is not None:
            H = F if H is None else H + F
        self.stats["hessians"] += 1
        self.seconds["hessian"] += self.clock() - t0
        return H if H is not None else sp.csr_matrix((self.n * self.dim,) * 2)

    def max_step(self, x0, x1) -> float:
        """The collision-free fraction of the straight move ``x0 -> x1`` (CCD), in ``[0, 1]``.

        The move's broad phase (candidate pairs whose boxes, swept over the move and inflated by
        ``dhat``, overlap) serves the CCD and is kept: the collision set of any configuration
        whose vertices all lie in their boxes swept by this move -- every line-search trial on
        it, the accepted iterate -- is built from it (:meth:`_within_sweep`) instead of from a
        broad phase of its own.
        """
        t0 = self.clock()
        V0, V1 = self.vertices(x0), self.vertices(x1)
        cand = self._ipc.Candidates()
        cand.build(self.mesh, V0, V1, self.dhat)
        self._sweep = (np.minimum(V0, V1), np.maximum(V0, V1), cand)
        t1 = self.clock()
        t = float(cand.compute_collision_free_stepsize(self.mesh, V0, V1, 0.0, self.ccd))
        self.stats["ccd_calls"] += 1
        self.seconds["broad_phase"] += t1 - t0
        self.seconds["ccd"] += self.clock() - t1
        return t

    def _within_sweep(self, V) -> bool:
        """Whether every collision vertex of ``V`` lies in its box swept by the last
        :meth:`max_step` move; then every pair closer than ``dhat`` at ``V`` is among that
        move's candidates (each primitive lies in its swept box, and the boxes are inflated by
        ``dhat``)."""
        if self._sweep is None:
            return False
        lo, hi, _ = self._sweep
        return bool(np.all(V >= lo) and np.all(V <= hi))

    def active(self, x) -> int:
        """The number of primitive pairs closer than ``dhat``."""
        return len(self._collisions(x)[1])

    def min_distance(self, x) -> float | None:
        """The smallest distance between surface primitives that may touch, when below
        :data:`REPORT_SCALE` ``* dhat`` (``None``: all farther)."""
        V, c = self._collisions(x, REPORT_SCALE * self.dhat)
        if not len(c):
            return None
        return float(np.sqrt(c.compute_minimum_distance(self.mesh, V)))

    # ------------------------------------------------------------------ stiffness
    def init_stiffness(self, grad_energy, average_mass: float, scale: float = 1.0, x=None) -> None:
        """IPC's initial stiffness (once, unless fixed): ``kappa`` minimising the gradient of the
        objective ``grad_energy + scale * kappa * grad b`` at ``x``, clamped to IPC's range from
        ``average_mass``; ``scale`` is the objective's weight of a potential (``h^2`` in implicit
        Euler, 1 in statics)."""
        if self.kappa is not None:
            return
        gb = scale * self.barrier_gradient(x).reshape(-1)
        k, kmax = self._ipc.initial_barrier_stiffness(
            self.length, self.barrier.barrier, self.dhat, float(average_mass),
            np.asarray(grad_energy, float).reshape(-1), gb)
        self.kappa, self.kappa_max = k / scale, kmax / scale
        self._prev_d = self._squared_min(x)

    def _squared_min(self, x) -> float:
        V, c = self._collisions(x)
        return float(c.compute_minimum_distance(self.mesh, V)) if len(c) else np.inf

    def update_stiffness(self, x) -> bool:
        """IPC's update after a Newton iteration: ``kappa`` doubles (up to its maximum) while the
        minimum distance keeps shrinking below ``1e-9`` of the scene; True when it changed."""
        if self.fixed_stiffness is not None or self.kappa is None:
            return False
        d = self._squared_min(x)
        new = self._ipc.update_barrier_stiffness(self._prev_d, d, self.kappa_max, self.kappa,
                                                 self.length)
        self._prev_d = d
        changed = new != self.kappa
        self.kappa = float(new)
        return bool(changed)

    # ------------------------------------------------------------------ moving obstacles
    def obstacles_at(self, t: float) -> np.ndarray:
        """The obstacles' vertices at time ``t`` by their prescribed motions
        (:meth:`~.surfaces.Obstacle.at`)."""
        return np.concatenate([np.zeros((0, self.dim))] + [ob.at(t) for ob in self.obstacles])

    def start_motion(self, t: float, h: float) -> None:
        """A step from ``t`` to ``t + h``: the obstacles' place at ``t + h`` the target of
        :meth:`advance` (they start where the last step left them, at ``t`` on the first).

        Friction sees each obstacle vertex's velocity over the step, ``(X(t + h) - X(t)) / h``:
        measured as implicit Euler measures the bodies' (``(x - x_n) / h``), so a body carried
        along with an obstacle -- a block on a turntable -- slides relative to it by nothing
        (the instantaneous ``v + omega x (x - p)`` would differ from the chord's velocity by
        ``|omega|^2 r h / 2`` at radius ``r``: a slip friction would fight every step).
        """
        if not self.moving:
            return
        if self._target is None:
            self.static = self.obstacles_at(t)
        self._target = self.obstacles_at(t + h)
        self.static_velocity = (self._target - self.static) / h
        self.advances = 0
        self._left = []                          # the way left before each move of the step

    def advance(self, x, pieces=None) -> bool:
        """Move the obstacles towards their step's end place as far as CCD allows with the
        bodies at ``x`` (they never pass through a body); True when they moved (the objective
        changed: solve again), False when they are there already.

        With ``pieces`` the bodies may move too: the pieces touching a moving obstacle (an
        active pair) are carried along with its rigid move (:meth:`_carries`), bodies and
        obstacles moving together in one straight move bounded by CCD, when that takes the
        obstacles farther than moving them alone -- so a body pushed or lifted by an obstacle
        keeps its gap instead of being approached by a fraction of the gap a move (a resting
        block struck by a paddle took ~80 moves of the paddle alone in one step). The new ``x``
        is written in place; Newton's solve from there is the bodies' response.

        Parameters
        ----------
        x : (n, d) float array
            The bodies' nodes (the integrator's iterate; written in place when carried).
        pieces : (n,) int array, optional
            The connected piece of every node, ``-1`` for a node never carried (pinned).

        Raises
        ------
        SolverError
            After :data:`MAX_ADVANCES` moves in one step without reaching the place, or when the
            last :data:`STALL_MOVES` moves gained under 1% of the way left (the bodies cannot
            get out of the way: caught between obstacles, held, or a step too long).
        """
        from ..errors import SolverError

        if self._target is None or np.array_equal(self.static, self._target):
            return False
        left = float(np.abs(self._target - self.static).max())
        self._left.append(left)
        stalled = self.advances >= STALL_MOVES and left > 0.99 * self._left[-1 - STALL_MOVES]
        if self.advances >= MAX_ADVANCES or stalled:
            why = f"{MAX_ADVANCES} moves" if not stalled else \
                f"{self.advances} moves, the last {STALL_MOVES} gaining under 1% of the way"
            raise SolverError(f"contact: a moving obstacle did not reach its place within one "
                              f"step ({why}; {left:.3g} short of it): the bodies cannot make "
                              "way for it (caught between obstacles, held, or too slow to "
                              "follow); use a smaller dt or a path that leaves them room")
        V0 = self.vertices(x)
        t, u = self._move_fraction(V0, None), None
        if t < 1.0 and pieces is not None:
            for carry in self._carries(x, pieces):
                tc = self._move_fraction(V0, carry)
                if tc > t:
                    t, u = tc, carry
        if u is not None:
            x += t * u
            self.stats["carries"] += 1
        self.static = self._target.copy() if t >= 1.0 else self.static + t * (self._target - self.static)
        self.advances += 1
        self.stats["obstacle_moves"] += 1
        return True

    def _move_fraction(self, V0, carry) -> float:
        """The collision-free fraction of the move of the obstacles to their target (and of the
        bodies by ``carry``, an ``(n, d)`` displacement) from ``V0``: CCD, then halved while the
        end place intersects (a guard: Tight-Inclusion's interval splitting can overflow on a
        pair already nearly touching, and then reports no impact)."""
        V1 = V0.copy()
        V1[self.nb:] = self._target
        if carry is not None:
            V1[:self.nb] += carry[self.surface_nodes]
        t0 = self.clock()
        t = float(self._ipc.compute_collision_free_stepsize(self.mesh, V0, V1,
                                                            narrow_phase_ccd=self.ccd))
        for _ in range(60):
            if t <= 0.0 or not self._ipc.has_intersections(
                    self.mesh, np.asfortranarray(V0 + t * (V1 - V0))):
                break
            t *= 0.5
        else:
            t = 0.0
        self.seconds["ccd"] += self.clock() - t0
        self.stats["ccd_calls"] += 1
        return t

    def _carries(self, x, pieces) -> list:
        """Candidate moves of the bodies, one per moving obstacle that a body touches: the
        pieces in an active pair with it (``pieces`` ``>= 0``) moved by its rigid move from
        its place now to its target (:func:`_rigid_fit`); ``(n, d)`` displacements."""
        V, c = self._collisions(x)
        touching: dict[int, set] = {}
        E, F = self.mesh.edges, self.mesh.faces
        for k in range(len(c)):
            ids = np.asarray(c[k].vertex_ids(E, F))
            ids = ids[ids >= 0]
            body, obst = ids[ids < self.nb], ids[ids >= self.nb]
            if not (len(body) and len(obst)):
                continue
            j = int(np.searchsorted(self._rows, obst[0] - self.nb, side="right")) - 1
            if self.obstacles[j].moving:
                touching.setdefault(j, set()).update(pieces[self.surface_nodes[body]].tolist())
        moves = []
        for j, near in sorted(touching.items()):
            near.discard(-1)
            if not near:
                continue
            nodes = np.isin(pieces, sorted(near))
            a, b = self._rows[j], self._rows[j + 1]
            R, p = _rigid_fit(self.static[a:b], self._target[a:b])
            u = np.zeros((self.n, self.dim))
            u[nodes] = x[nodes] @ R.T + p - x[nodes]
            moves.append(u)
        return moves

    # ------------------------------------------------------------------ friction
    def lag_friction(self, x_start, x_basis, h: float) -> None:
        """Freeze the friction of a step from ``x_start`` of length ``h``: normal forces and
        tangent bases at ``x_basis`` (``x_start`` first, the step's solution at a lagging
        iteration)."""
        if self.friction is None:
            return
        V, c = self._collisions(x_basis)
        tc = self._ipc.TangentialCollisions()
        if len(c):
            tc.build(self.mesh, V, c, self._ipc.BarrierPotential(self.dhat, self.kappa_value),
                     self.mu)
        self._lag = (np.asarray(x_start, float).reshape(self.n, self.dim).copy(), float(h), tc)

    def end_step(self) -> None:
        """Friction is off outside a step (it lives on the step's velocity)."""
        self._lag = None

    def _velocities(self, x):
        xs, h, tc = self._lag
        return self.vertices((np.asarray(x, float).reshape(self.n, self.dim) - xs) / h), h, tc

    def _friction_active(self) -> bool:
        return self._lag is not None and len(self._lag[2]) > 0

    def _friction_energy(self, x) -> float:
        if not self._friction_active():
            return 0.0
        W, h, tc = self._velocities(x)
        W[self.nb:] = self.static_velocity
        return h * float(self.friction(tc, self.mesh, W))

    def _friction_gradient(self, x) -> np.ndarray:
        if not self._friction_active():
            return np.zeros((self.n, self.dim))
        W, h, tc = self._velocities(x)
        W[self.nb:] = self.static_velocity
        return self._to_nodes(self.friction.gradient(tc, self.mesh, W))

    def _friction_hessian(self, x, how):
        if not self._friction_active():
            return None
        W, h, tc = self._velocities(x)
        W[self.nb:] = self.static_velocity
        return self._to_dofs(self.friction.hessian(tc, self.mesh, W, how)) / h

    # ------------------------------------------------------------------ checks
    def check_intersection_free(self, x, where: str = "initial state") -> None:
        """Raise a one-line InputError naming a pair of intersecting surface elements of ``x``
        (the independent test :func:`~.check.intersecting_pairs`), or a pair at distance 0."""
        from .check import intersecting_pairs

        V = self.vertices(x)
        pairs = intersecting_pairs(V, self.faces, self._allowed_faces)
        if len(pairs):
            i, j = pairs[0]
            raise InputError(f"contact: the {where} intersects: {self.describe_face(i)} "
                             f"crosses {self.describe_face(j)} ({len(pairs)} intersecting "
                             "pair(s)); move the bodies apart")
        d = self.min_distance(x)
        if d is not None and d <= 0.0:
            raise InputError(f"contact: the {where} has surfaces touching (distance 0); move "
                             "the bodies apart")

    def _allowed_faces(self, i, j) -> np.ndarray:
        fi, fj = self.faces[i, 0], self.faces[j, 0]
        dynamic = (fi < self.nb) | (fj < self.nb)
        if self.self_contact:
            return dynamic
        return dynamic & (self.component[fi] != self.component[fj])

    def describe_face(self, k: int) -> str:
        """``'surface triangle 12 (nodes 3, 4, 9)'`` or ``'obstacle triangle 2'``."""
        kind = "triangle" if self.faces.shape[1] == 3 else "segment"
        body = len(self.faces) - self.n_obstacle_faces
        if k < body:
            nodes = ", ".join(str(int(self.surface_nodes[v])) for v in self.faces[k])
            return f"surface {kind} {k} (nodes {nodes})"
        return f"obstacle {kind} {k - body}"

    def intersections(self, x) -> int:
        """How many pairs of surface elements of ``x`` intersect (the independent test)."""
        from .check import intersecting_pairs

        return len(intersecting_pairs(self.vertices(x), self.faces, self._allowed_faces))


def _rigid_fit(A, B):
    """``(R, p)``: the rotation and translation taking the points ``A`` nearest to ``B`` (least
    squares, Kabsch 1976, "A solution for the best rotation to relate two sets of vectors",
    Acta Cryst. A32), ``B ~ A R^T + p``."""
    ca, cb = A.mean(axis=0), B.mean(axis=0)
    U, _, Vt = np.linalg.svd((A - ca).T @ (B - cb))
    D = np.eye(A.shape[1])
    D[-1, -1] = np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0
    R = Vt.T @ D @ U.T
    return R, cb - ca @ R.T
