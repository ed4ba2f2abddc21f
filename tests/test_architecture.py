"""The layering of femkit, checked from the source: library layers never reach the application.

Layers: ``mesh -> fem -> solvers <- dynamics`` (and ``solids``, elastic bodies, beside dynamics,
which never imports it: the elastic force takes a body object) know nothing of files; ``case`` (case and scene
files), ``study`` and ``cli`` sit on top. Every import is read from the AST of every module,
imports inside functions (lazy ones) included, and no string names an application module for
importlib to load.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "femkit"
LIBRARY = ("mesh", "fem", "solvers", "dynamics", "solids")
APPLICATION = ("case", "study", "cli")


def _modules(layer: str) -> list[Path]:
    return sorted((PKG / layer).rglob("*.py"))


def _imports_of(source: str, package: list[str]) -> set[str]:
    """Absolute names of every femkit module ``source`` imports, anywhere in it, with
    relative imports resolved against ``package`` (e.g. ``["femkit", "dynamics"]``)."""
    out = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.add(mod)
            out |= {f"{mod}.{a.name}" for a in node.names}
    return {m for m in out if m == "femkit" or m.startswith("femkit.")}


def _imported(path: Path) -> set[str]:
    rel = path.relative_to(PKG.parent).with_suffix("")
    return _imports_of(path.read_text(encoding="utf-8"), list(rel.parts[:-1]))


def _forbidden(names: set[str], layers) -> list[str]:
    return sorted(n for n in names for layer in layers
                  if n == f"femkit.{layer}" or n.startswith(f"femkit.{layer}."))


@pytest.mark.parametrize("layer", LIBRARY)
def test_library_layers_never_import_the_application(layer):
    files = _modules(layer)
    assert len(files) > 3
    bad = {str(p.relative_to(PKG)): _forbidden(_imported(p), APPLICATION) for p in files}
    assert not {k: v for k, v in bad.items() if v}


@pytest.mark.parametrize("layer", LIBRARY)
def test_library_layers_do_not_write_femkit_files(layer):
    """femkit.io (atomic result directories, result.json/CSV writers, figures) is the
    application's; meshes are read and written by femkit.mesh itself."""
    bad = {str(p.relative_to(PKG)): _forbidden(_imported(p), ("io",)) for p in _modules(layer)}
    assert not {k: v for k, v in bad.items() if v}


@pytest.mark.parametrize("layer, below", [("mesh", ("fem", "solvers", "dynamics", "solids")),
                                          ("solvers", ("mesh", "fem", "dynamics", "solids")),
                                          ("fem", ("dynamics", "solids")),
                                          ("solids", ("dynamics",))],
                         ids=["mesh", "solvers", "fem", "solids"])
def test_lower_layers_do_not_import_higher_library_layers(layer, below):
    bad = {str(p.relative_to(PKG)): _forbidden(_imported(p), below) for p in _modules(layer)}
    assert not {k: v for k, v in bad.items() if v}


def test_no_package_root_import_from_inside():
    """``from .. import __version__`` points back up at the package root: use femkit._version."""
    bad = []
    for p in PKG.rglob("*.py"):
        if p.parent == PKG:
            continue
        if "femkit" in _imported(p):
            bad.append(str(p.relative_to(PKG)))
    assert not bad


IMPORT_STRING = re.compile(r"^femkit\.(case|study|cli)[\w.]*:[\w.]+$")


def test_no_import_strings_reach_the_application():
    """No ``"femkit.case.x:attr"`` string for importlib to resolve (a hidden upward import)."""
    bad = []
    for p in PKG.rglob("*.py"):
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) \
                    and IMPORT_STRING.match(node.value):
                bad.append(f"{p.relative_to(PKG)}: {node.value!r}")
    assert not bad


def test_the_checker_sees_lazy_and_relative_imports():
    """The walk finds an import inside a function body and resolves it (so the tests can fail)."""
    src = "import numpy\ndef f():\n    from ..case.load import load_case\n    return load_case\n"
    names = _imports_of(src, ["femkit", "dynamics"])
    assert "femkit.case.load" in names
    assert _forbidden(names, APPLICATION) == ["femkit.case.load", "femkit.case.load.load_case"]
    assert IMPORT_STRING.match("femkit.dynamics.scene:run_scene") is None
    assert IMPORT_STRING.match("femkit.case.scene.run:run_scene")


def test_sources_cite_publications_not_documents_outside_the_repository():
    """The repository stands alone: no module or test refers to the lecture source documents kept
    outside it, by their name or by their relative path (docs/methods.md lists the real sources)."""
    root = PKG.parent
    words = ("se" + "ed", "../" + "shared")
    bad = [f"{p.relative_to(root)}:{i + 1}"
           for d in (PKG, root / "tests") for p in d.rglob("*.py")
           for i, line in enumerate(p.read_text(encoding="utf-8").splitlines())
           if any(w in line for w in words)]
    assert not bad
