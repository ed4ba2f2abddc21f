"""The layering of femkit, checked from the source: library layers never reach the application.

Layers: ``mesh -> fem -> solvers <- dynamics`` know nothing of files; ``case`` (case and scene
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
LIBRARY = ("mesh", "fem", "solvers", "dynamics")
APPLICATION = ("case", "study", "cli")


def _modules(layer: str) -> list[Path]:
    return sorted((PKG / layer).rglob("*.py"))


def _import_statements(source: str, package: list[str]):
    """``(module, names)`` of every import statement anywhere in ``source`` (``names`` empty
    for ``import module``), relative imports resolved against ``package`` (e.g.
    ``["femkit", "dynamics"]``)."""
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, []
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            yield mod, [a.name for a in node.names]


def _imports_of(source: str, package: list[str]) -> set[str]:
    """Absolute names of every femkit module ``source`` imports, anywhere in it, with
    relative imports resolved against ``package`` (e.g. ``["femkit", "dynamics"]``)."""
    out = set()
    for mod, names in _import_statements(source, package):
        out.add(mod)
        out |= {f"{mod}.{n}" for n in names}
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


@pytest.mark.parametrize("layer, below", [("mesh", ("fem", "solvers", "dynamics")),
                                          ("solvers", ("mesh", "fem", "dynamics")),
                                          ("fem", ("dynamics",))],
                         ids=["mesh", "solvers", "fem"])
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


# ----------------------------------------------------------------------------- import cycles
#: Packages whose modules must not import each other in a cycle (extend to "femkit" as a whole
#: once the application layers are free of cycles too).
NO_CYCLES = ("mesh", "fem", "solvers", "dynamics")


def _module_graph(pkg: Path = PKG) -> dict[str, set[str]]:
    """Module -> the femkit modules it imports (lazy imports included). A name imported from
    a package is an import of that submodule when it is one (``from . import defaults``), else
    of the package's ``__init__``; the implicit import of parent packages is not an edge."""
    def name_of(p: Path) -> str:
        parts = list(p.relative_to(pkg.parent).with_suffix("").parts)
        return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)

    files = {name_of(p): p for p in pkg.rglob("*.py")}
    graph = {}
    for name, path in files.items():
        package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        edges = set()
        for mod, names in _import_statements(path.read_text(encoding="utf-8"), package):
            subs = {f"{mod}.{n}" for n in names} & files.keys()
            edges |= subs
            if mod in files and (not names or len(subs) < len(names)):
                edges.add(mod)
        graph[name] = edges - {name}
    return graph


def _cycles(graph: dict[str, set[str]], within: str) -> list[list[str]]:
    """The strongly connected components of more than one module among ``within``'s modules
    (Tarjan's algorithm), each sorted."""
    nodes = {n for n in graph if n == within or n.startswith(within + ".")}
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v] & nodes:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while not comp or comp[-1] != v:
                comp.append(stack.pop())
                on.discard(comp[-1])
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


@pytest.mark.parametrize("layer", NO_CYCLES)
def test_no_import_cycle_inside_the_layer(layer):
    assert _cycles(_module_graph(), f"femkit.{layer}") == []


def test_the_cycle_checker_finds_cycles_and_resolves_submodule_imports():
    graph = {"femkit.a": {"femkit.a.x"}, "femkit.a.x": {"femkit.a.y"},
             "femkit.a.y": {"femkit.a.x"}, "femkit.a.z": set()}
    assert _cycles(graph, "femkit.a") == [["femkit.a.x", "femkit.a.y"]]
    g = _module_graph()
    assert "femkit.solvers.defaults" in g["femkit.solvers.registry"]   # `from . import defaults`
    assert "femkit.solvers" not in g["femkit.solvers.registry"]        # ... not the package
