"""Compiled kernels of an energy of the principal stretches, generated from its SymPy tree.

For an energy ``W(s1, s2, s3)`` (plane strain: ``s3 = 1``) the derivatives ``dW/ds_i`` and
``d^2W/ds_i ds_j`` are taken symbolically once, common subexpressions are shared
(:func:`sympy.cse`) and the three are printed as one numba function
``energy(s, params, grad, hess) -> W`` per dimension -- the signature of the hand-written
energies of :mod:`femkit.elements.compiled`. The generated module then carries the *same* point and
element kernels as the built-in materials: the source of every compiled function that reaches
``stretch_energy`` through its calls (:func:`copied_kernels`: the stretch point function, the
point dispatch, the element pass and any inlined bodies of theirs) is copied in unchanged, so
their global ``stretch_energy`` resolves to the generated energy and everything else (signed SVD, SVD
derivative, repeated-stretch limits, PSD projection, CSR assembly) is shared code, inlined by numba
as for the built-ins. No Python runs per element.

The module is written once to a cache directory (``FEMKIT_CACHE_DIR``, else
``~/.cache/femkit``) under a name that hashes the energy, the constants' order and the source of
:mod:`femkit.elements.compiled` (so an edit there regenerates it: numba's cache would not notice an
edited callee), and numba caches its machine code beside it; a later process pays neither SymPy
nor compilation.
"""

from __future__ import annotations

import hashlib
import inspect
import sys
from pathlib import Path
from types import ModuleType
from typing import Callable, Sequence

from ...codegen import cache_dir as _cache_dir, copied_kernels as _copied_kernels, load_named

__all__ = ["energy_module", "energy_source", "module_key", "cache_dir", "module_cached"]


def cache_dir() -> Path:
    """Where generated energy modules live (``FEMKIT_CACHE_DIR`` or ``~/.cache/femkit``)."""
    return _cache_dir("energies")


def _energy_function(name: str, W, d: int, n_params: int) -> str:
    """Source of ``name(s, params, grad, hess) -> W`` for ``d`` stretches (``W`` over the
    symbols ``s_1..s_d`` and ``c_0..``)."""
    import sympy
    from sympy.printing.pycode import PythonCodePrinter

    s = sympy.symbols(f"s_1:{d + 1}")
    grad = [sympy.diff(W, si) for si in s]
    hess = [sympy.diff(grad[i], s[j]) for i in range(d) for j in range(i, d)]
    reps, reduced = sympy.cse([W, *grad, *hess], symbols=sympy.numbered_symbols("t"))
    pr = PythonCodePrinter({"fully_qualified_modules": True, "standard": "python3"})
    lines = ["@numba.njit(cache=True, fastmath=False)",
             f"def {name}(s, params, grad, hess):  # pragma: no cover - compiled"]
    lines += [f"    s_{i + 1} = s[{i}]" for i in range(d)]
    lines += [f"    c_{k} = params[{k}]" for k in range(n_params)]
    lines += [f"    {sym} = {pr.doprint(expr)}" for sym, expr in reps]
    for i in range(d):
        lines.append(f"    grad[{i}] = {pr.doprint(reduced[1 + i])}")
    k = 1 + d
    for i in range(d):
        for j in range(i, d):
            lines.append(f"    hess[{i}, {j}] = {pr.doprint(reduced[k])}")
            if j != i:
                lines.append(f"    hess[{j}, {i}] = hess[{i}, {j}]")
            k += 1
    lines.append(f"    return {pr.doprint(reduced[0])}")
    if any("not supported" in ln.lower() for ln in lines):
        from ...errors import MaterialError

        raise MaterialError(f"energy {W}: uses a function the kernel generator cannot print")
    return "\n".join(lines)


def copied_kernels(module) -> list[str]:
    """Names of the compiled functions of ``module`` that reach ``stretch_energy`` through their
    calls: these are copied into a generated module, so that they resolve the generated energy;
    the others are imported (:func:`femkit.codegen.copied_kernels`)."""
    return _copied_kernels(module, ("stretch_energy",))


def _dispatch(n: int) -> list[str]:
    """``stretch_energy(code, ...)``: energy number ``code`` (1-based) of the module's ``n``."""
    lines = ["@numba.njit(cache=True)",
             "def stretch_energy(code, s, params, grad, hess):  # pragma: no cover - compiled",
             "    if s.shape[0] == 2:"]
    for dim in (2, 3):
        if dim == 3:
            lines.append("    else:")
        for k in range(1, n):
            lines += [f"        if code == {k}:",
                      f"            return energy_{dim}_{k}(s, params, grad, hess)"]
        lines.append(f"        return energy_{dim}_{n}(s, params, grad, hess)")
    return lines


def energy_source(energies: Sequence) -> str:
    """The text of the generated module of ``energies``, a sequence of ``(W, stretches,
    constants)``: ``W`` a SymPy expression of the three symbols ``stretches`` and the symbols
    ``constants``, whose values come in that order as ``params``. Energy ``k`` (from 1) is
    number ``k`` of the module's ``stretch_energy`` (the ``code`` of the kernels)."""
    import sympy

    from ...elements import compiled

    s = sympy.symbols("s_1:4")
    parts = ['"""Generated by femkit.solids.energy.codegen: do not edit.', ""]
    funcs: list[str] = []
    for k, (W, stretches, constants) in enumerate(energies, start=1):
        safe = {**{a: b for a, b in zip(stretches, s)},
                **{c: sympy.Symbol(f"c_{i}") for i, c in enumerate(constants)}}
        W3 = sympy.piecewise_fold(W.xreplace(safe).rewrite(sympy.Piecewise))
        W2 = W3.subs(s[2], 1)
        parts.append(f"energy {k}: W(s1, s2, s3) = {W3}")
        funcs += ["", "", _energy_function(f"energy_2_{k}", W2, 2, len(constants)),
                  "", "", _energy_function(f"energy_3_{k}", W3, 3, len(constants))]
    copied = copied_kernels(compiled)
    shared = [n for n in vars(compiled) if not n.startswith("__") and n not in copied
              and n != "stretch_energy" and n != "annotations"]
    parts += ['"""', "", "import math", "", "import numba", "import numpy as np", "",
              f"from femkit.elements.compiled import {', '.join(sorted(shared))}", *funcs, "", "",
              *_dispatch(len(energies)), ""]
    for name in copied:
        src = inspect.getsource(getattr(compiled, name)).rstrip()
        if f"def {name}(" not in src:   # the file was edited after this process imported it
            from ...errors import MaterialError

            raise MaterialError(f"{compiled.__file__} changed since it was imported; restart to "
                                "generate kernels from it")
        parts += ["", src, ""]
    return "\n".join(parts)


def _version(dist: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(dist)
    except PackageNotFoundError:  # pragma: no cover - SymPy is a dependency
        return "?"


def module_key(recipe: str) -> str:
    """Name of the generated module of ``recipe`` (the energies' text and their constants'
    names): a hash of it, of the sources of :mod:`femkit.elements.compiled` and of this generator
    and of SymPy's version -- everything the generated text depends on, known without SymPy."""
    from ...elements import compiled

    text = "\n".join([recipe, inspect.getsource(compiled), inspect.getsource(sys.modules[__name__]),
                      _version("sympy")])
    return "femkit_energy_" + hashlib.sha256(text.encode()).hexdigest()[:20]


def module_cached(recipe: str) -> bool:
    """Whether the module of ``recipe`` is generated and its element pass in numba's cache
    beside it: a run then loads both and compiles nothing (else it says it compiles first)."""
    from ...codegen import find_generated

    name = module_key(recipe)
    path = find_generated(name, "energies")
    return path is not None and \
        any((path.parent / "__pycache__").glob(f"{name}.element_pass-*.nbi"))


def energy_module(recipe: str, build: Callable[[], Sequence]) -> ModuleType:
    """The compiled kernels of the energies ``build()`` returns (``(W, stretches, constants)``
    each, :func:`energy_source`): a module with ``stretch_energy``, ``point`` and
    ``element_pass`` taking the arguments of :mod:`femkit.elements.compiled`'s.

    ``recipe`` names the energies in text (their expressions and the constants' order); the
    module is found by :func:`module_key` of it, so a later process loads it (and numba its
    machine code) without running SymPy or ``build`` at all. Written once, atomically.

    Generating it (SymPy's derivatives) is bounded in time (:func:`.parse.sympy_time_limit`)
    and stops at once on a signal inside :func:`femkit.interrupt.stop_on_signals`."""
    from ...interrupt import raising
    from .parse import sympy_time_limit

    def make_text() -> str:
        with raising("the energy's derivatives"), sympy_time_limit(_short(recipe)):
            return energy_source(build())

    return load_named(module_key(recipe), "energies", make_text)


def _short(text: str) -> str:
    return text if len(text) <= 100 else text[:97] + "..."
