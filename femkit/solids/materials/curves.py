"""Stress-stretch curves of a material: uniaxial tension/compression with free lateral faces.

The body is stretched by ``s`` along one axis; the two lateral stretches ``t`` relax until their
principal stress vanishes, ``dW/ds_2 (s, t, t) = 0`` (a scalar root, bracketed), and the
nominal (first Piola-Kirchhoff) stress along the axis is ``dW/ds_1 (s, t, t)`` (3D). The curve of a material designed by its energy shows at once whether
it stiffens in tension, softens in compression, or (StVK) collapses.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from ...errors import MaterialError
from .base import StretchMaterial

__all__ = ["uniaxial_curve", "plot_stress_stretch"]


def uniaxial_curve(material: StretchMaterial, stretches) -> tuple[np.ndarray, np.ndarray]:
    """``(lateral stretches t, nominal stress P_11)`` of uniaxial loading at each axial stretch
    (module docstring). Raises :class:`~femkit.errors.MaterialError` when no lateral stretch in
    ``(0.05, 20)`` makes the lateral stress vanish."""
    from scipy.optimize import brentq

    def lateral(t, s):
        return material.stretch_derivatives([s, t, t])[1][1]

    s_all = np.asarray(stretches, dtype=float)
    t_out, p_out = np.empty_like(s_all), np.empty_like(s_all)
    grid = np.geomspace(0.05, 20.0, 200)
    for k, s in enumerate(s_all):
        vals = np.array([lateral(t, s) for t in grid])
        sign = np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))
        if not sign.size:
            raise MaterialError(f"{material.name}: no free lateral stretch at axial stretch {s:g}")
        i = sign[np.argmin(np.abs(grid[sign] - 1.0))]        # the root nearest the rest state
        t = brentq(lateral, grid[i], grid[i + 1], args=(s,), xtol=1e-14)
        t_out[k] = t
        p_out[k] = material.stretch_derivatives([s, t, t])[1][0]
    return t_out, p_out


def plot_stress_stretch(materials: Mapping[str, StretchMaterial], path, *,
                        stretches=None, title: str = "uniaxial stress-stretch") -> None:
    """Plot :func:`uniaxial_curve` of each ``{label: material}`` into the image ``path`` (nominal
    stress over the shear modulus of the first material, against the stretch)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = np.linspace(0.6, 1.6, 81) if stretches is None else np.asarray(stretches, dtype=float)
    mu0 = next(iter(materials.values())).mu
    fig, ax = plt.subplots(figsize=(5.2, 3.6), dpi=100)
    for label, mat in materials.items():
        ax.plot(s, uniaxial_curve(mat, s)[1] / mu0, label=label)
    ax.axhline(0.0, color="0.7", lw=0.8)
    ax.axvline(1.0, color="0.7", lw=0.8)
    ax.set_xlabel("axial stretch s")
    ax.set_ylabel("nominal stress P11 / mu")
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
