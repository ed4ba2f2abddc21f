"""The refinement kernels' warm-up calls them with every argument type a hierarchy does, so a
large run after ``femkit warmup`` compiles no refinement kernel: numba types a read-only array
apart from a writable one, and a hierarchy refines each level with the read-only edges the
previous refinement left on it."""

from __future__ import annotations

import importlib

import numba
import pytest

from femkit.mesh import MeshHierarchy, generate
from femkit.mesh import _refine_kernel as kernel

# the module (the package exports a function of the same name)
refine_module = importlib.import_module("femkit.mesh.refine")


@pytest.mark.parametrize("geometry, dim, name, threshold", [
    ("unit_square", 2, "interleaved_red", "NUMBA_THRESHOLD"),
    ("unit_cube", 3, "interleaved_bey", "NUMBA_THRESHOLD_3D"),
], ids=["triangles", "tetrahedra"])
def test_a_hierarchy_calls_the_refinement_with_warmed_up_types(geometry, dim, name, threshold,
                                                                monkeypatch):
    real = getattr(kernel, name)
    calls: list[tuple] = []

    def spy(*args):
        calls.append(tuple(numba.typeof(a) for a in args))
        return real(*args)

    monkeypatch.setattr(kernel, name, spy)
    kernel.warm_up(dims=(dim,))
    warmed = set(calls)
    calls.clear()
    monkeypatch.setattr(refine_module, threshold, 0)  # the compiled route at every level
    MeshHierarchy.from_refinement(generate(geometry, 0.5), 3, renumber="rcm")  # as fmg does
    assert len(calls) == 3
    assert set(calls) <= warmed, "a hierarchy's refinement types not compiled by the warm-up"
