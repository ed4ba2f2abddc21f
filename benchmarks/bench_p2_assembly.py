"""P2 assembly benchmark: femkit's P2 stiffness + load against scikit-fem's, same run, same meshes.

Run by hand:  python benchmarks/bench_p2_assembly.py [--n2 500] [--n3 40] [--repeat 3]

Meshes: femkit's structured unit square with ``n2 x n2`` squares (2 n2^2 triangles, (2 n2 + 1)^2
P2 dofs: n2 = 500 gives 1,002,001) and the Kuhn cube with ``n3^3`` cubes (6 n3^3 tetrahedra,
(2 n3 + 1)^3 P2 dofs: n3 = 40 gives 531,441; n3 = 50 gives 1,030,301 and needs ~15 GB in
scikit-fem); both libraries get the same points and cells. Timed, medians of interleaved runs
(femkit and scikit-fem alternate within each repetition; the machine is shared):

- ``skfem``: ``Basis(MeshTri/MeshTet(p, t), ElementTriP2/ElementTetP2())`` (its default
  quadrature, degree 4, exact for P2's mass and load products) + ``laplace.assemble`` +
  the load of ``f = sin(x) y (+ z)`` (``LinearForm``);
- ``femkit first``: ``assemble_matrix(mesh, "stiffness", element="P2")`` + ``element_load`` on a
  new mesh object, so the dof map (the mesh's edges) and the CSR pattern are built in the call (the
  first call of a run); numba kernels loaded from the on-disk cache (warmed before timing).

The two matrices are compared (femkit's dof order, :func:`femkit.case.poisson.reference.femkit_order`)
so the ratio is of equal work. BLAS and numba threads are pinned to 1 before numpy is imported
(femkit's kernels are serial anyway), so each side runs on one core: besides the wall-clock medians
the CPU seconds of the process (``time.process_time``, user + system) are reported, a ratio that
the other jobs of a shared machine move less.
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import gc  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402


def _source(dim: int):
    if dim == 2:
        return lambda x, y: np.sin(x) * y
    return lambda x, y, z: np.sin(x) * y + z


def femkit_p2(points, cells, f):
    """K and F of P2 on a new mesh object (dof map, pattern, values: a first call)."""
    from femkit.fem.forms import assemble_matrix
    from femkit.fem.lagrange import element_load
    from femkit.mesh import Mesh

    mesh = Mesh(points, cells)
    t0, c0 = time.perf_counter(), time.process_time()
    K = assemble_matrix(mesh, "stiffness", 1.0, element="P2")
    F = element_load(mesh, f, "P2")
    return (time.perf_counter() - t0, time.process_time() - c0), K, F, mesh


def skfem_p2(points, cells, f):
    import skfem
    from skfem.models.poisson import laplace

    t0, c0 = time.perf_counter(), time.process_time()
    if points.shape[1] == 2:
        basis = skfem.Basis(skfem.MeshTri(points.T.copy(), cells.T.copy(), sort_t=False), skfem.ElementTriP2())
    else:
        basis = skfem.Basis(skfem.MeshTet(points.T.copy(), cells.T.copy(), sort_t=False), skfem.ElementTetP2())
    K = laplace.assemble(basis)
    F = skfem.LinearForm(lambda v, w: f(*w.x) * v).assemble(basis)
    return (time.perf_counter() - t0, time.process_time() - c0), K, F, basis


def measure(name: str, mesh, repeat: int) -> dict:
    from femkit.case.poisson.reference import femkit_order

    f = _source(mesh.dim)
    points, cells = np.ascontiguousarray(mesh.points), np.ascontiguousarray(mesh.cells)
    fk, sk = [], []
    for i in range(repeat):
        t, K, F, m = femkit_p2(points, cells, f)
        fk.append(t)
        if i == 0:
            n_dofs, nnz = K.shape[0], K.nnz
            t, Ks, Fs, basis = skfem_p2(points, cells, f)
            order = femkit_order(m, basis, "P2")
            Ks = Ks.tocsr()[order][:, order]
            dK = abs(K - Ks).max() / abs(Ks).max()
            dF = np.abs(F - Fs[order]).max() / np.abs(Fs).max()
            del Ks, Fs, basis, order
        else:
            t = skfem_p2(points, cells, f)[0]
        sk.append(t)
        del K, F, m
        gc.collect()
    out = {"mesh": name, "cells": mesh.n_cells, "dofs": n_dofs, "nnz": nnz,
           "femkit_s": statistics.median(t[0] for t in fk), "skfem_s": statistics.median(t[0] for t in sk),
           "femkit_cpu": statistics.median(t[1] for t in fk), "skfem_cpu": statistics.median(t[1] for t in sk),
           "max_rel_diff_K": float(dK), "max_rel_diff_F": float(dF)}
    out["ratio"] = out["skfem_s"] / out["femkit_s"]
    out["cpu_ratio"] = out["skfem_cpu"] / out["femkit_cpu"]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n2", type=int, default=500, help="squares per side of the 2D mesh")
    ap.add_argument("--n3", type=int, default=40, help="cubes per side of the 3D mesh")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    from femkit.fem import _element_kernels, _kernels
    from femkit.mesh import _edges_kernel, structured_box, structured_mesh

    for module in (_kernels, _element_kernels, _edges_kernel):  # numba: loaded from the cache
        module.warm_up()                                         # (or compiled once) before any timing
    rows = []
    if args.n2:
        rows.append(measure(f"square {args.n2}x{args.n2}", structured_mesh(args.n2, args.n2), args.repeat))
    if args.n3:
        n = args.n3
        rows.append(measure(f"cube {n}^3", structured_box(n, n, n), args.repeat))
    print(f"{'mesh':<16} {'cells':>9} {'P2 dofs':>9} {'nnz':>10} {'femkit s':>9} {'skfem s':>8} "
          f"{'skfem/femkit':>12} {'cpu: femkit':>11} {'skfem':>7} {'ratio':>6} {'|dK|':>8} {'|dF|':>8}")
    for r in rows:
        print(f"{r['mesh']:<16} {r['cells']:>9} {r['dofs']:>9} {r['nnz']:>10} {r['femkit_s']:>9.3f} "
              f"{r['skfem_s']:>8.3f} {r['ratio']:>12.1f} {r['femkit_cpu']:>11.3f} {r['skfem_cpu']:>7.3f} "
              f"{r['cpu_ratio']:>6.1f} {r['max_rel_diff_K']:>8.1e} {r['max_rel_diff_F']:>8.1e}")


if __name__ == "__main__":
    main()
