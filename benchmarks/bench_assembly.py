"""Assembly benchmark: femkit P1 stiffness + load against scikit-fem, same run, same meshes.

Run by hand:  python benchmarks/bench_assembly.py [--kmax 10] [--repeat 3]

BLAS threads are pinned to 1 before numpy is imported.  Meshes are scikit-fem's
``MeshTri().refined(k)`` (2 * 4**k triangles; k = 10 has 2.1M).  Printed per mesh (medians):

- ``skfem``: ``Basis(mesh, ElementTriP1(), intorder=1)`` + ``asm(laplace)`` + ``asm(unit_load)``
  (scikit-fem 12's intorder=1 on triangles is its 3-point rule);
- ``skfem 1pt``: the same with the centroid rule passed explicitly (``quadrature=``), its fastest
  configuration (last ratio column);
- ``femkit first``: a first assembly on a new mesh (builds the CSR pattern) + load;
- ``femkit repeat``: stiffness with the cached pattern (new coefficient, same mesh) + load;
- the pattern build alone and the ratios skfem / femkit.

The numba kernel's compile (or on-disk cache load) time is reported once at start.
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402


def median_time(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kmin", type=int, default=6)
    ap.add_argument("--kmax", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    from skfem import Basis, ElementTriP1, MeshTri, asm
    from skfem.models.poisson import laplace, unit_load

    from femkit.fem import SparsityPattern, assemble_load, assemble_stiffness
    from femkit.mesh import Mesh

    t0 = time.perf_counter()
    from femkit.fem._kernels import pattern_kernel

    tiny = MeshTri()
    pattern_kernel(tiny.t.T, tiny.p.shape[1])
    print(f"numba import + pattern kernel compile/cache load: {time.perf_counter() - t0:.2f} s")

    hdr = (f"{'k':>2} {'elements':>9} {'skfem':>8} {'skfem 1pt':>9} {'pattern':>8} {'fk first':>9} {'fk repeat':>9} "
           f"{'K only':>8} {'F only':>8} {'ratio first':>11} {'ratio repeat':>12} {'repeat vs 1pt':>13}")
    print(hdr)
    for k in range(args.kmin, args.kmax + 1):
        sk = MeshTri().refined(k)
        mesh = Mesh(sk.p.T, sk.t.T)
        rep = args.repeat

        def skfem_assembly():
            basis = Basis(sk, ElementTriP1(), intorder=1)
            asm(laplace, basis)
            asm(unit_load, basis)

        t_sk = median_time(skfem_assembly, rep)
        centroid = (np.array([[1 / 3], [1 / 3]]), np.array([0.5]))

        def skfem_centroid():
            basis = Basis(sk, ElementTriP1(), quadrature=centroid)
            asm(laplace, basis)
            asm(unit_load, basis)

        t_sk1 = median_time(skfem_centroid, rep)

        def first():
            pat = SparsityPattern.from_mesh(mesh)
            assemble_stiffness(mesh, 1.0, pattern=pat)
            assemble_load(mesh, 1.0)

        t_first = median_time(first, rep)
        t_pat = median_time(lambda: SparsityPattern.from_mesh(mesh), rep)
        pat = SparsityPattern.from_mesh(mesh)
        t_K = median_time(lambda: assemble_stiffness(mesh, 2.0, pattern=pat), rep)
        t_F = median_time(lambda: assemble_load(mesh, 1.0), rep)
        t_rep = median_time(lambda: (assemble_stiffness(mesh, 2.0, pattern=pat), assemble_load(mesh, 1.0)), rep)
        print(f"{k:>2} {mesh.n_triangles:>9} {t_sk:8.3f} {t_sk1:9.3f} {t_pat:8.3f} {t_first:9.3f} {t_rep:9.3f} "
              f"{t_K:8.3f} {t_F:8.3f} {t_sk / t_first:10.1f}x {t_sk / t_rep:11.1f}x {t_sk1 / t_rep:12.1f}x", flush=True)


if __name__ == "__main__":
    main()
