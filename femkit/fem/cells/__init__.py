"""Compiled per-cell geometry (:mod:`femkit.fem.cells.kernels`), the leaf of :mod:`femkit.fem`."""
