"""Every third-party import femkit makes is declared in pyproject.toml.

A fresh virtual environment has exactly what ``pip install -e .`` installs: a module femkit imports
that no declared distribution provides works on a developer's machine and fails on a user's (sympy
did, in every solid case). The scan walks the AST of every module under ``femkit/``, lazy imports
inside functions and ``importlib.import_module("...")`` literals included, and maps each top-level
module to the distribution that provides it:

- a core dependency (``[project] dependencies``) may be imported anywhere;
- a distribution of an optional extra only in a module whose text names that extra (``[extra]``),
  so a user who lacks it is told what to install.
"""

from __future__ import annotations

import ast
import importlib.metadata as metadata
import re
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "femkit"

#: Import names of distributions that are not installed in every test environment (the optional
#: extras' compiled libraries), so ``packages_distributions`` cannot map them there.
NOT_ALWAYS_INSTALLED = {
    "sksparse": "scikit-sparse",
    "cholespy": "cholespy",
    "petsc4py": "petsc4py",
    "mpi4py": "mpi4py",
    "mkl": "mkl",
}


def _normalise(name: str) -> str:
    """PEP 503 normalised distribution name."""
    return re.sub(r"[-_.]+", "-", name).lower()


def _requirement_name(requirement: str) -> str:
    return _normalise(re.split(r"[\s<>=!~;\[]", requirement.strip(), maxsplit=1)[0])


def declared() -> tuple[set[str], dict[str, set[str]]]:
    """Core dependencies and, per extra, the distributions it adds (normalised names)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    core = {_requirement_name(r) for r in project["dependencies"]}
    extras = {extra: {_requirement_name(r) for r in reqs}
              for extra, reqs in project.get("optional-dependencies", {}).items()}
    return core, extras


def _imported_names(tree: ast.AST) -> set[str]:
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
        elif (isinstance(node, ast.Call) and node.args
              and getattr(node.func, "attr", getattr(node.func, "id", None)) == "import_module"
              and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)):
            names.add(node.args[0].value.split(".")[0])
    return names


def third_party_imports() -> dict[str, set[Path]]:
    """Top-level third-party module name -> the femkit files that import it."""
    found: dict[str, set[Path]] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        for name in _imported_names(ast.parse(path.read_text(), str(path))):
            if name in sys.stdlib_module_names or name in ("femkit", "__future__"):
                continue
            found.setdefault(name, set()).add(path)
    return found


def distribution_of(module: str) -> str | None:
    """The distribution that provides top-level ``module`` here, or None when unknown."""
    dists = metadata.packages_distributions().get(module)
    if dists:
        return _normalise(dists[0])
    dist = NOT_ALWAYS_INSTALLED.get(module)
    return _normalise(dist) if dist else None


IMPORTS = third_party_imports()


def test_the_scan_sees_lazy_and_string_imports():
    """The scan is not vacuous: it sees imports made inside functions and by ``import_module``."""
    tree = ast.parse("def f():\n    import gmsh\n    importlib.import_module('pyamg.aggregation')\n")
    assert _imported_names(tree) == {"gmsh", "pyamg"}
    assert {"numpy", "scipy", "numba", "sympy", "gmsh"} <= set(IMPORTS)


@pytest.mark.parametrize("module", sorted(IMPORTS), ids=str)
def test_every_import_is_declared(module):
    core, extras = declared()
    dist = distribution_of(module)
    files = sorted(str(p.relative_to(ROOT)) for p in IMPORTS[module])
    assert dist is not None, (f"{module!r} (imported by {files}) is provided by no installed "
                              f"distribution and is not a known optional one")
    if dist in core:
        return
    owning = sorted(extra for extra, dists in extras.items() if dist in dists)
    assert owning, (f"{module!r} (distribution {dist!r}, imported by {files}) is declared neither "
                    f"as a dependency nor in an extra of pyproject.toml")
    for path in IMPORTS[module]:
        text = path.read_text()
        assert any(f"[{extra}]" in text for extra in owning), (
            f"{path.relative_to(ROOT)} imports {module!r} of the extra(s) {owning} but its text "
            f"names none of them: the error a user gets must say what to install")


def test_sympy_is_a_core_dependency():
    """Solid materials' energies are parsed by SymPy in every solid case (the regression)."""
    core, _ = declared()
    assert "sympy" in core
