"""An energy of the principal stretches as written by a user, and its checks at rest.

Xu, Sin, Zhu & Barbic (2015, "Nonlinear material design using principal stretches", ACM TOG
34(4)) show that an isotropic hyperelastic material is its energy density of the principal
stretches, conveniently in the *separable* form

``W = sum_i f(s_i) + sum_{i<j} g(s_i s_j) + h(s_1 s_2 s_3)``

(``f`` and ``g`` written in the variable ``s``, ``h`` in ``J``), or any full ``W`` of ``s1, s2,
s3`` (and ``J = s1 s2 s3``) symmetric in the stretches. Constants are named (``mu``, ``lam``,
anything) and their values given separately. Plane strain (2D) is ``s3 = 1``.

:meth:`Energy.check` is what a material runs at construction: the energy and its derivatives are
finite at rest, the rest state is stress-free (``dW/ds = 0`` at ``s = 1``), the linearisation at
rest is a stable isotropic elasticity with the Lame-equivalent moduli
``mu = (W_11 - W_12) / 2``, ``lam = W_12`` (``mu > 0``, bulk modulus ``lam + 2 mu / 3 > 0``), and
a full ``W`` is symmetric in the stretches.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Mapping

from ...errors import MaterialError
from .parse import parse_energy

__all__ = ["Energy", "RestModuli"]

_STRETCHES = ("s1", "s2", "s3")


@dataclass(frozen=True)
class RestModuli:
    """Lame-equivalent moduli of an energy linearised at rest."""

    mu: float
    lam: float

    @property
    def bulk(self) -> float:
        return self.lam + 2.0 * self.mu / 3.0

    def __str__(self) -> str:
        return f"mu = {self.mu:.6g}, lambda = {self.lam:.6g}, bulk modulus = {self.bulk:.6g}"


@dataclass(frozen=True)
class Energy:
    """An energy density of the principal stretches: ``W`` or the separable ``f, g, h``
    (strings; see the module docstring). Omitted parts of the separable form are zero.

    >>> Energy(f="mu*(s-1)**2", h="lam/2*(J-1)**2").symbolic(["mu", "lam"])
    lam*(s1*s2*s3 - 1)**2/2 + mu*(s1 - 1)**2 + mu*(s2 - 1)**2 + mu*(s3 - 1)**2
    """

    W: str | None = None
    f: str | None = None
    g: str | None = None
    h: str | None = None

    def __post_init__(self):
        if (self.W is None) == (self.f is None and self.g is None and self.h is None):
            raise MaterialError("an energy is either a full W(s1, s2, s3) or the separable "
                                "f(s), g(s), h(J) (Xu et al. 2015), not both and not neither")

    @property
    def separable(self) -> bool:
        return self.W is None

    def describe(self) -> str:
        if self.W is not None:
            return f"W = {self.W}"
        return ", ".join(f"{k} = {v}" for k, v in (("f", self.f), ("g", self.g), ("h", self.h))
                         if v is not None)

    def symbolic(self, constants):
        """``W(s1, s2, s3)`` as a SymPy expression over the symbols ``s1, s2, s3`` and the
        ``constants`` (names)."""
        import sympy

        s = sympy.symbols(_STRETCHES)
        consts = {}
        for c in constants:
            if not isinstance(c, str) or not c.isidentifier():
                raise MaterialError(f"constant name {c!r} is not an identifier")
            if c in _STRETCHES or c in ("s", "J", "pi", "E"):
                raise MaterialError(f"constant name {c!r} is reserved (stretches s, s1, s2, s3, "
                                    "J and pi, E)")
            consts[c] = sympy.Symbol(c)
        J = s[0] * s[1] * s[2]
        if self.W is not None:
            return parse_energy(self.W, {**consts, "s1": s[0], "s2": s[1], "s3": s[2], "J": J})
        v = sympy.Symbol("s")
        W = sympy.Integer(0)
        if self.f is not None:
            f = parse_energy(self.f, {**consts, "s": v})
            W += sum(f.subs(v, si) for si in s)
        if self.g is not None:
            g = parse_energy(self.g, {**consts, "s": v})
            W += sum(g.subs(v, a * b) for a, b in itertools.combinations(s, 2))
        if self.h is not None:
            W += parse_energy(self.h, {**consts, "J": v}).subs(v, J)
        return W

    def check(self, W, values: Mapping[str, float], name: str = "energy") -> RestModuli:
        """The checks at rest (module docstring) of ``W = self.symbolic(values)`` with the
        constants' ``values``; returns the Lame-equivalent moduli.

        Raises
        ------
        MaterialError
            One line naming the failed check and the offending value.
        """
        import sympy

        s = sympy.symbols(_STRETCHES)
        sub = {sympy.Symbol(k): sympy.Float(v, 17) for k, v in values.items()}
        Wc = W.xreplace(sub)
        free = sorted(str(x) for x in Wc.free_symbols - set(s))
        if free:
            raise MaterialError(f"{name}: no value for the constant(s) {', '.join(free)}")
        rest = {si: 1 for si in s}

        def at_rest(expr, what):
            try:
                v = complex(expr.subs(rest).evalf(17))
            except (TypeError, ValueError, ZeroDivisionError):
                v = complex("nan")
            if not (math.isfinite(v.real) and math.isfinite(v.imag)) or abs(v.imag) > 0.0:
                raise MaterialError(f"{name}: {what} is not finite (or not real) at rest "
                                    f"s = (1, 1, 1): {v}")
            return v.real

        W0 = at_rest(Wc, "the energy W")
        g = [sympy.diff(Wc, si) for si in s]
        H = [[sympy.diff(g[i], s[j]) for j in range(3)] for i in range(3)]
        g0 = [at_rest(gi, f"dW/ds{i + 1}") for i, gi in enumerate(g)]
        H0 = [[at_rest(H[i][j], f"d2W/ds{i + 1}ds{j + 1}") for j in range(3)] for i in range(3)]
        scale = max(max(abs(v) for row in H0 for v in row), abs(W0), 1e-300)
        if max(abs(v) for v in g0) > 1e-10 * scale:
            raise MaterialError(
                f"{name}: the rest state is not stress-free: principal stresses dW/ds = "
                f"({', '.join(f'{v:.6g}' for v in g0)}) at s = (1, 1, 1); subtract the linear "
                "term so that the undeformed body is at rest")
        if not self.separable:
            self._check_symmetric(Wc, s, name)
        moduli = RestModuli(0.5 * (H0[0][0] - H0[0][1]), H0[0][1])
        if not (moduli.mu > 0.0 and moduli.bulk > 0.0):
            raise MaterialError(f"{name}: unstable at rest (need mu > 0 and a positive bulk "
                                f"modulus lambda + 2 mu / 3): {moduli}")
        return moduli

    @staticmethod
    def _check_symmetric(W, s, name: str) -> None:
        """``W`` unchanged by every permutation of the stretches, at a few fixed points."""
        points = [(1.3, 0.8, 1.1), (0.7, 1.6, 0.9), (2.1, 1.05, 0.55)]
        for p in points:
            vals = [complex(W.subs(dict(zip(s, perm))).evalf(17))
                    for perm in itertools.permutations(p)]
            ref = max(abs(v) for v in vals) or 1.0
            if max(abs(v - vals[0]) for v in vals) > 1e-10 * ref:
                raise MaterialError(
                    f"{name}: W(s1, s2, s3) is not symmetric in the stretches (an isotropic "
                    f"material's must be): at s = {p} its permutations give "
                    f"{min(v.real for v in vals):.6g} .. {max(v.real for v in vals):.6g}")
