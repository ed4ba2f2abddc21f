"""Nothing keeps a list of names beside its registry.

A literal (tuple, list, set or dict, with the literals it holds two levels down) in femkit's source
that names three or more entries of one registry -- solvers, preconditioners, integrators, materials, problem and
study kinds, the warm-up's compiled kernels -- is a hand-kept table: it goes stale the day an
entry is added (the warm-up's kernel list, the study prices' solves per integrator and the
work-precision families were such tables). What the application needs from an entry is declared
on the entry and derived from the registry.

Left out, each for its stated reason:

* ``__all__``: the functions a module exports (``cg``, ``pcg`` ... as functions, not names of
  registry entries);
* the value of a schema's ``"default"``: the choice a study makes when its file names none (the
  same data a bundled file holds, overridable);
* :data:`KNOWN`, the tables still waiting for their derivation, each with the reason.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import femkit

PACKAGE = Path(femkit.__file__).resolve().parent

#: file (relative to the package) -> why its name table is still there. Empty it, never grow it.
KNOWN: dict[str, str] = {}


def _registries() -> dict[str, set[str]]:
    import femkit.case  # noqa: F401  (the problem kinds' finders)
    import femkit.study  # noqa: F401  (the study kinds' finders)
    from femkit.case.poisson import warmup
    from femkit.dynamics.integrators import INTEGRATORS
    from femkit.kinds import KINDS
    from femkit.solids.materials import MATERIALS
    from femkit.solvers.registry import PRECONDITIONERS, SOLVERS

    return {"solver": set(SOLVERS.names()), "preconditioner": set(PRECONDITIONERS.names()),
            "integrator": set(INTEGRATORS.names()), "material": set(MATERIALS.names()),
            "kind": set(KINDS.names()),
            "kernel": {k.name for k in warmup._registry().kernels()}}


def _skipped(tree: ast.AST) -> set[int]:
    """ids of the literals left out: ``__all__``'s and the values of ``"default"`` keys."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
                out.add(id(node.value))
        if isinstance(node, ast.Dict):
            out.update(id(v) for k, v in zip(node.keys, node.values)
                       if isinstance(k, ast.Constant) and k.value == "default")
    return out


LITERALS = (ast.Tuple, ast.List, ast.Set, ast.Dict)


def _strings(node: ast.AST, skipped: set[int], depth: int = 2) -> set[str]:
    """The strings of the literal ``node``: its elements (a dict's keys and values) and, ``depth``
    levels down, those of the literals among them (a table of ``(module, kernel)`` pairs), the
    skipped literals left out. A schema's enum three dicts down is not this table's."""
    if id(node) in skipped or depth < 0:
        return set()
    if isinstance(node, ast.Constant):
        return {node.value} if isinstance(node.value, str) else set()
    if not isinstance(node, LITERALS):
        return set()
    children = ([*filter(None, node.keys), *node.values] if isinstance(node, ast.Dict)
                else node.elts)
    return set().union(*(_strings(c, skipped, depth - 1) for c in children))


def name_tables(source: str, registries: dict[str, set[str]]) -> list[tuple[int, str, list[str]]]:
    """``(line, registry, names)`` of every literal in ``source`` naming three or more entries of
    one registry (the outermost such literal only)."""
    tree = ast.parse(source)
    skipped, found, inside = _skipped(tree), [], set()
    for node in ast.walk(tree):
        if not isinstance(node, LITERALS) or id(node) in inside:
            continue
        strings = _strings(node, skipped)
        hits = [(registry, sorted(strings & names)) for registry, names in registries.items()]
        hits = [(node.lineno, registry, hit) for registry, hit in hits if len(hit) >= 3]
        if hits:
            found += hits
            inside.update(id(n) for n in ast.walk(node))
    return found


def test_no_name_list_outside_its_registry():
    registries = _registries()
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel in KNOWN:
            continue
        for line, registry, names in name_tables(path.read_text(encoding="utf-8"), registries):
            found.append(f"femkit/{rel}:{line}: {registry} names {names}")
    assert found == [], "name tables beside their registries:\n" + "\n".join(found)


def test_the_known_tables_are_still_tables():
    """An entry of :data:`KNOWN` whose table is gone must leave :data:`KNOWN` too."""
    registries = _registries()
    for rel in KNOWN:
        assert name_tables((PACKAGE / rel).read_text(encoding="utf-8"), registries), rel


@pytest.mark.parametrize("source, expected", [
    # the warm-up's former list of kernels: pairs of (module, kernel) nested in a dict
    ('F = {"estimate": (("m", "residual_pass"), ("m", "slot_fluxes"), ("m", "triangle_areas"))}',
     [(1, "kernel", ["residual_pass", "slot_fluxes", "triangle_areas"])]),
    # the study prices' former solves per integrator
    ('S = {"newton": 4.0, "projective": 2.0, "fast_mass_spring": 2.0}',
     [(1, "integrator", ["fast_mass_spring", "newton", "projective"])]),
    ('__all__ = ["cg", "pcg", "jacobi"]', []),
    ('s = {"default": ["linear", "stvk", "corotational"]}', []),
    ('pair = ("cg", "pcg")', []),
])
def test_the_scan_finds_a_table(source, expected):
    """The scan itself: it sees tables (nested ones too) and leaves out what it says it does."""
    assert name_tables(source, _registries()) == expected
