"""Test systems for the solver layer: small, deterministic, SPD (unless named otherwise)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp


def laplace_1d(m: int) -> sp.csr_matrix:
    return sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(m, m), format="csr")


def poisson_2d(m: int) -> sp.csr_matrix:
    """5-point Laplacian on an m x m interior grid (Dirichlet), n = m^2, unscaled."""
    T, eye = laplace_1d(m), sp.identity(m, format="csr")
    return (sp.kron(T, eye) + sp.kron(eye, T)).tocsr()


def anisotropic_2d(m: int, eps: float = 1e-3) -> sp.csr_matrix:
    """``-eps u_xx - u_yy``, 5-point."""
    T, eye = laplace_1d(m), sp.identity(m, format="csr")
    return (eps * sp.kron(eye, T) + sp.kron(T, eye)).tocsr()


def high_contrast_2d(m: int, contrast: float = 1e6, blocks: int = 4) -> sp.csr_matrix:
    """Cell-centred finite volumes on an m x m grid, kappa = 1 / contrast on a blocks x blocks
    checkerboard, harmonic-mean face transmissibilities, Dirichlet walls (half-cell)."""
    i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
    kappa = np.where(((i * blocks) // m + (j * blocks) // m) % 2 == 0, 1.0, contrast)
    idx = np.arange(m * m).reshape(m, m)
    rows, cols, vals = [], [], []
    diag = np.zeros((m, m))
    for axis in (0, 1):
        k1 = kappa.take(np.arange(m - 1), axis=axis)
        k2 = kappa.take(np.arange(1, m), axis=axis)
        t = 2.0 * k1 * k2 / (k1 + k2)
        a = idx.take(np.arange(m - 1), axis=axis).ravel()
        c = idx.take(np.arange(1, m), axis=axis).ravel()
        rows += [a, c]
        cols += [c, a]
        vals += [-t.ravel(), -t.ravel()]
        np.add.at(diag.reshape(-1), a, t.ravel())
        np.add.at(diag.reshape(-1), c, t.ravel())
        for end in (0, m - 1):  # wall faces at half a cell: transmissibility 2 kappa
            sl = [slice(None), slice(None)]
            sl[axis] = end
            diag[tuple(sl)] += 2.0 * kappa[tuple(sl)]
    rows.append(idx.ravel())
    cols.append(idx.ravel())
    vals.append(diag.ravel())
    A = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(m * m, m * m))
    return A


CASES = {
    "poisson": lambda: poisson_2d(20),
    "contrast": lambda: high_contrast_2d(20),
    "aniso": lambda: anisotropic_2d(20),
}


@pytest.fixture(scope="session")
def systems():
    """name -> (A, b, x_exact by scipy spsolve)."""
    from scipy.sparse.linalg import spsolve

    out = {}
    rng = np.random.default_rng(0)
    for name, make in CASES.items():
        A = make()
        b = rng.standard_normal(A.shape[0])
        out[name] = (A, b, spsolve(A.tocsc(), b))
    return out


@pytest.fixture(scope="session")
def builders():
    return {"poisson": poisson_2d, "aniso": anisotropic_2d, "contrast": high_contrast_2d,
            "laplace_1d": laplace_1d}
