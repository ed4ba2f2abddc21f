"""Projective dynamics per frame (run by hand):
``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_projective.py [--quick] [--cells 40 12 12]``.

A clamped tetrahedral beam (``--cells`` cubes of 6 tetrahedra; default 40 x 12 x 12 = 34,560
tetrahedra, 20,787 dofs; ``--quick``: 20 x 6 x 6) with the as-rigid-as-possible energy
(co-rotational, ``lam = 0``), gravity and a random initial velocity; one implicit-Euler frame
``h = 1/60`` three ways, in one run, one thread:

* femkit's ``projective`` integrator, 10 iterations (CHOLMOD factor kept for the run, compiled
  local step); the one-off factorisation reported separately;
* Newton's method on the same implicit-Euler objective, converged (``||dx||_inf <= 1e-10`` times
  the beam length): per iteration femkit's compiled gradient + projected Hessian
  (:meth:`femkit.solids.ElasticBody.evaluate`) and a CHOLMOD factorisation
  (:func:`femkit.solvers.cholesky.factorize_spd`, as the ``newton`` integrator's ``cholesky``
  path, which does not take elastic forces yet); time per step and per iteration;
* the same projective loop written with SciPy only (``scipy.sparse.linalg.splu`` of the same
  matrix, a batched ``np.linalg.svd`` local step, ``np.add.at`` scatter): what a user would write.

The error of a projective frame is stated against the converged Newton frame:
``max |x_PD - x*| / max |x* - x_n|`` (relative to the frame's displacement). Median of 3 after a
warm-up. Goal (issue): a 10-iteration frame <= 1/5 of a Newton step.

``--kernels``: the materials' element pass (gradient + projected Hessian, a randomly perturbed
box of ~100k tetrahedra; ``--quick`` ~10k), in one run: each built-in (kernels generated from its
energy expression, all built-ins in one module dispatching on the material's number: the
runtime path) against its designed twin (the same expression given as a user's energy,
:func:`femkit.solids.materials.designed`: a module of its own); elements per second and the
ratio.
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def _median_time(fn, repeat: int = 3):
    fn()
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts)), out


def scene(cells, mu: float = 2e4, rho: float = 1000.0):
    from femkit.dynamics.forces import Gravity
    from femkit.dynamics.system import elastic_system
    from femkit.mesh.structured import structured_box
    from femkit.solids import Corotational, ElasticBody

    nx, ny, nz = cells
    mesh = structured_box(nx, ny, nz, (nx / ny, 1.0, nz / ny))
    body = ElasticBody(mesh.points, mesh.cells, Corotational(mu, 0.0, rho))
    clamp = np.flatnonzero(mesh.points[:, 0] < 1e-12)
    rng = np.random.default_rng(1)
    v0 = 0.5 * rng.standard_normal(mesh.points.shape)
    v0[clamp] = 0.0
    return body, elastic_system(body, pinned=clamp, v0=v0, forces=[Gravity(9.81)])


def newton_frame(body, system, xn, vn, h, tol: float = 1e-10):
    """Converged Newton step of implicit Euler (full steps; the ARAP objective with ``M/h^2``
    needs no line search here), CHOLMOD factorisations. Returns ``(x, iterations)``."""
    import scipy.sparse as sp

    from femkit.solvers.cholesky import factorize_spd

    free = np.flatnonzero(~system.pinned)
    dof = (3 * free[:, None] + np.arange(3)).ravel()
    Mh = sp.diags(np.repeat(system.mass, 3) / (h * h))
    y = xn + h * vn
    x = y.copy()
    x[system.pinned] = xn[system.pinned]
    fg = system.constant_force()
    length = float(np.ptp(xn, axis=0).max())
    for it in range(1, 100):
        _, g, H, _ = body.evaluate(x, 2, project=True)
        grad = ((x - y) * system.mass[:, None] / (h * h) + g - fg).ravel()
        K = (Mh + H).tocsr()[dof][:, dof]
        dx = factorize_spd(K.tocsc(), ordering="nesdis", mode="simplicial").solve(-grad[dof])
        x.reshape(-1)[dof] += dx
        if np.abs(dx).max() <= tol * length:
            return x, it
    return x, it


class ScipyProjective:
    """The projective loop with SciPy/NumPy only (the user's version)."""

    def __init__(self, body, system, h):
        import scipy.sparse as sp
        from scipy.sparse.linalg import splu

        from femkit.dynamics.integrators.projective import arap_laplacian

        r = body.rest
        self.r, self.h = r, h
        self.w = 2.0 * body.groups[0][1].mu * r.volumes
        self.free = np.flatnonzero(~system.pinned)
        self.pin = np.flatnonzero(system.pinned)
        A = (sp.diags(system.mass) + h * h * arap_laplacian(body, self.w)).tocsc()
        self.lu = splu(A[self.free][:, self.free].tocsc(), permc_spec="MMD_AT_PLUS_A")
        self.A_fp = A[self.free][:, self.pin]
        self.M = system.mass[:, None]
        self.fg = system.constant_force()

    def frame(self, xn, vn, iterations: int = 10):
        r, h = self.r, self.h
        x = xn + h * vn
        x[self.pin] = xn[self.pin]
        const = self.M * x + h * h * self.fg
        for _ in range(iterations):
            F = np.einsum("mna,mnb->mab", x[r.cells], r.gradients)
            U, _, Vt = np.linalg.svd(F)
            R = U @ Vt
            neg = np.linalg.det(R) < 0
            U[neg, :, -1] *= -1
            R[neg] = U[neg] @ Vt[neg]
            T = self.w[:, None, None] * np.einsum("mab,mnb->mna", R, r.gradients)
            rhs = const.copy()
            np.add.at(rhs, r.cells, h * h * T)
            b = rhs[self.free] - self.A_fp @ xn[self.pin]
            x[self.free] = self.lu.solve(b)
        return x


def kernels(quick: bool, repeat: int) -> None:
    from femkit.mesh.structured import structured_box
    from femkit.solids import ElasticBody
    from femkit.solids.materials import designed, material

    n = (12, 12, 12) if quick else (26, 26, 25)
    mesh = structured_box(*n)
    x = mesh.points + 0.02 * np.random.default_rng(0).standard_normal(mesh.points.shape)
    m = len(mesh.cells)
    print(f"element pass, gradient + projected Hessian, {m} tetrahedra")
    print(f"{'material':20s} {'built-in':>14s} {'designed twin':>14s} {'twin/built-in':>14s}")
    for name in ("linear", "corotational", "stvk", "stable_neo_hookean"):
        builtin = material(name, E=1e4, nu=0.3)
        times = []
        for mat in (builtin, designed(builtin)) if name != "linear" else (builtin,):
            body = ElasticBody(mesh.points, mesh.cells, mat)
            times.append(_median_time(lambda: body.evaluate(x, 2, project=True), repeat)[0])
        twin = (f"{m / times[1]:11.3g} e/s {times[1] / times[0]:14.2f}" if len(times) > 1
                else f"{'-':>14s} {'-':>14s}")
        print(f"{name:20s} {m / times[0]:11.3g} e/s {twin}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--cells", type=int, nargs=3, default=None)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--kernels", action="store_true")
    args = ap.parse_args(argv)
    if args.kernels:
        return kernels(args.quick, args.repeat)
    from femkit.dynamics.integrators import StepContext, get_integrator
    from femkit.solvers import SolverSpec

    cells = args.cells or ((20, 6, 6) if args.quick else (40, 12, 12))
    body, system = scene(cells)
    h = 1.0 / 60.0
    print(f"beam {cells}: {body.rest.n_cells} tetrahedra, {system.n * 3} dofs, "
          f"{int((~system.pinned).sum()) * 3} free; h = {h:.4g}")

    def make(name, **opts):
        integ = get_integrator(name, **opts)
        ctx = StepContext(linear_solver=SolverSpec("cholesky"))
        st = integ.start(system, system.x0, system.v0, 0.0, h, ctx)
        return integ, ctx, st

    pd, pd_ctx, st = make("projective", iterations=10)
    t0 = time.perf_counter()
    pd._operators(system, h, pd_ctx)
    t_setup = time.perf_counter() - t0
    t_pd, x_pd = _median_time(lambda: pd.step(system, st, h, pd_ctx).x, args.repeat)

    t_nt, (x_nt, its) = _median_time(lambda: newton_frame(body, system, st.x, st.v, h),
                                     args.repeat)

    user = ScipyProjective(body, system, h)
    t_sp, x_sp = _median_time(lambda: user.frame(st.x, st.v, 10), args.repeat)

    disp = np.abs(x_nt - st.x).max()
    err = lambda x: np.abs(x - x_nt).max() / disp  # noqa: E731
    errs = {k: err(pd.__class__(iterations=k).step(system, st, h, pd_ctx).x) for k in (5, 20, 40)}
    print(f"{'method':42s} {'ms/frame':>9s} {'ratio':>7s} {'rel. error':>10s}")
    print(f"{'projective, 10 iterations (femkit)':42s} {1e3 * t_pd:9.1f} {1.0:7.2f} {err(x_pd):10.2e}")
    print(f"{'projective, 10 iterations (SciPy only)':42s} {1e3 * t_sp:9.1f} {t_sp / t_pd:7.2f} "
          f"{err(x_sp):10.2e}")
    print(f"{f'newton, converged ({its} iterations)':42s} {1e3 * t_nt:9.1f} {t_nt / t_pd:7.2f} "
          f"{0.0:10.2e}")
    print(f"newton per iteration {1e3 * t_nt / its:.1f} ms; projective setup (factorisation, once) "
          f"{1e3 * t_setup:.1f} ms; PD frame / Newton step = {t_pd / t_nt:.3f} (goal <= 0.2)")
    print("projective error at 5 / 20 / 40 iterations: "
          + " / ".join(f"{v:.2e}" for v in errs.values()))


if __name__ == "__main__":
    main()
