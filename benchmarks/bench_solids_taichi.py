"""femkit's element pass against Taichi's CPU backend (run by hand, one thread).

Taichi is not a femkit dependency: run this in an environment that has both, e.g.
``python -m venv --system-site-packages ti-env && ti-env/bin/pip install taichi`` then
``OPENBLAS_NUM_THREADS=1 PYTHONPATH=. ti-env/bin/python benchmarks/bench_solids_taichi.py``.

The Taichi kernel is the force kernel of Taichi's own implicit FEM example
(``taichi/examples/simulation/implicit_fem.py``, ``get_force_func``: ``ti.svd``, the signed SVD,
the co-rotational stress ``P = 2 mu (F - R)`` and the scatter to the four vertices), on the same
structured box of tetrahedra as ``bench_solids.py`` (~100k), ``cpu_max_num_threads=1``, in
float32 (the example's type) and float64. The example has no Hessian kernel of its own (its
implicit step multiplies with the constant linear stiffness, matrix-free), so the comparison is
per element for the gradient: femkit's co-rotational gradient pass (``level=1``), and femkit's
gradient + projected Hessian for scale. Both give the same forces (checked, float64) before timing.
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def _median(fn, repeats=5):
    fn()
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="~10k tetrahedra")
    args = ap.parse_args(argv)
    import taichi as ti

    from femkit.mesh.structured import structured_box
    from femkit.solids import ElasticBody, material

    n = (14, 14, 9) if args.quick else (30, 30, 19)
    mesh = structured_box(*n)
    mu = 1.0
    body = ElasticBody.from_mesh(mesh, material("corotational", mu=mu, lam=0.0))
    rng = np.random.default_rng(0)
    x = body.rest_positions + 0.01 * rng.standard_normal(body.rest_positions.shape)
    m = body.rest.n_cells
    ref = -body.gradient(x)                                 # femkit's force

    rows = []
    for dtype, name in ((ti.f32, "float32"), (ti.f64, "float64")):
        ti.reset()
        ti.init(arch=ti.cpu, cpu_max_num_threads=1, default_fp=dtype, offline_cache=True,
                log_level=ti.ERROR)
        verts = ti.Vector.field(4, dtype=ti.i32, shape=m)
        X = ti.Vector.field(3, dtype=dtype, shape=body.n)
        f = ti.Vector.field(3, dtype=dtype, shape=body.n)
        B = ti.Matrix.field(3, 3, dtype=dtype, shape=m)
        W = ti.field(dtype=dtype, shape=m)
        cells = body.rest.cells
        verts.from_numpy(cells.astype(np.int32))
        X.from_numpy(x)
        # the example's rest data: Ds with vertex 3 as the origin, B = Dm^-1, W = volume
        P0 = body.rest_positions
        Dm = np.stack([P0[cells[:, i]] - P0[cells[:, 3]] for i in range(3)], axis=2)
        B.from_numpy(np.linalg.inv(Dm))
        W.from_numpy(body.rest.volumes)

        @ti.func
        def ssvd(F):
            U, sig, V = ti.svd(F)
            if U.determinant() < 0:
                for i in ti.static(range(3)):
                    U[i, 2] *= -1
                sig[2, 2] = -sig[2, 2]
            if V.determinant() < 0:
                for i in ti.static(range(3)):
                    V[i, 2] *= -1
                sig[2, 2] = -sig[2, 2]
            return U, sig, V

        @ti.kernel
        def get_force():
            for u in f:
                f[u] = ti.Vector([0.0, 0.0, 0.0])
            for c in verts:
                v = verts[c]
                F = ti.Matrix.cols([X[v[i]] - X[v[3]] for i in range(3)]) @ B[c]
                U, sig, V = ssvd(F)
                P = 2 * mu * (F - U @ V.transpose())
                H = -W[c] * P @ B[c].transpose()
                for i in ti.static(range(3)):
                    force = ti.Vector([H[j, i] for j in range(3)])
                    f[v[i]] += force
                    f[v[3]] -= force

        get_force()
        err = np.abs(f.to_numpy() - ref).max() / np.abs(ref).max()
        t = _median(lambda: (get_force(), ti.sync()))
        rows.append((f"Taichi CPU ({name}): the example's force kernel", t, err))

    rows.append(("femkit compiled: co-rotational gradient (float64)",
                 _median(lambda: body.evaluate(x, 1)), 0.0))
    rows.append(("femkit compiled: gradient + projected Hessian", 
                 _median(lambda: body.evaluate(x, 2, project=True)), 0.0))
    print(f"{m} tetrahedra, {body.n} nodes, co-rotational, one thread")
    print(f"{'what':<52}{'seconds':>10}{'k elements/s':>14}{'max rel. diff':>15}")
    for what, t, err in rows:
        print(f"{what:<52}{t:>10.4f}{m / t / 1e3:>14.0f}{err:>15.1e}")


if __name__ == "__main__":
    main()
