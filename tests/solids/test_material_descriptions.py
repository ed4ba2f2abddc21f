"""What ``femkit list materials`` and docs/materials.md say of a built-in material is its energy.

The stable neo-Hookean entry is the log-free, rest-stable form of Smith, de Goes & Kim (2018): its
description's formula, read by SymPy, equals the energy the code compiles, and that energy is
the paper's ``mu/2 (I_C - 3) + lam'/2 (J - alpha)^2`` (``alpha = 1 + mu/lam'``, ``lam' = lam + mu``)
less a constant, with no ``log(I_C + 1)`` term.
"""

import re
from pathlib import Path

import pytest

from femkit.catalog import entries
from femkit.solids.materials.builtin_materials import MATERIALS

sympy = pytest.importorskip("sympy")
from sympy.parsing.sympy_parser import (  # noqa: E402
    convert_xor, implicit_multiplication, parse_expr, standard_transformations)

DOCS = Path(__file__).resolve().parents[2] / "docs"
s1, s2, s3, mu, lam = sympy.symbols("s1 s2 s3 mu lam")
NAMES = {"s1": s1, "s2": s2, "s3": s3, "mu": mu, "lam": lam,
         "I_C": s1**2 + s2**2 + s3**2, "J": s1 * s2 * s3}


def _read(text: str):
    return parse_expr(text, local_dict=NAMES,
                      transformations=standard_transformations + (implicit_multiplication, convert_xor))


def _compiled(name: str):
    return MATERIALS.get(name).energy_expression.symbolic(["mu", "lam"])


def test_stable_neo_hookean_description_is_the_compiled_energy():
    text = dict(entries("materials"))["stable_neo_hookean"]
    assert "log" not in text.split(":", 1)[1]  # the listed formula has no log term
    formula = text.split(": ", 1)[1].rstrip(".")
    assert sympy.simplify(_read(formula) - _compiled("stable_neo_hookean").subs(
        {sympy.Symbol("s1"): s1, sympy.Symbol("s2"): s2, sympy.Symbol("s3"): s3,
         sympy.Symbol("mu"): mu, sympy.Symbol("lam"): lam})) == 0


def test_stable_neo_hookean_is_smith_et_al_rest_stable_form_without_the_log_term():
    W = _compiled("stable_neo_hookean").subs({sympy.Symbol(k): v for k, v in NAMES.items()
                                             if k in ("s1", "s2", "s3", "mu", "lam")})
    lam_p = lam + mu
    alpha = 1 + mu / lam_p
    smith = mu / 2 * (NAMES["I_C"] - 3) + lam_p / 2 * (NAMES["J"] - alpha) ** 2
    assert sympy.simplify(W - smith + mu**2 / (2 * lam_p)) == 0
    assert not W.has(sympy.log)


def test_list_materials_keeps_abbreviations_in_the_first_sentence():
    assert dict(entries("materials"))["stvk"].startswith("St. Venant-Kirchhoff mu |E|^2")


@pytest.mark.parametrize("name", [n for n in MATERIALS.names()
                                  if getattr(MATERIALS.get(n), "energy_expression", None)])
def test_docs_materials_table_is_the_compiled_energy(name):
    """docs/materials.md's table of built-in energies holds each one's exact text."""
    rows = re.findall(r"^\| [^|]+ \| `([^`]+)` \|$", (DOCS / "materials.md").read_text(), re.M)
    compact = [r.replace(" ", "") for r in rows]
    assert MATERIALS.get(name).energy_expression.W.replace(" ", "") in compact
