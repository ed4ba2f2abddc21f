"""No import cycles between femkit modules, nor between its packages; lazy and string imports included.

The module import graph is read from the AST of every module: an edge ``a -> b`` for every
``import`` or ``from ... import`` in ``a`` (at module level or inside a function), ``b`` being
the module named (``from pkg import name`` names the submodule ``pkg.name`` when there is one,
else the package ``pkg``), and for every string constant naming a femkit module for importlib to
load: ``"femkit.x.y"`` or ``"femkit.x.y:attr"`` (an import in all but syntax; a module's string
naming itself is not). Imports under
``if TYPE_CHECKING:`` never run and are left out. A cycle is a strongly connected component of
more than one node (Tarjan 1972), or a node importing itself; the tests list every component, so
one run shows every cycle to break.

The package graph folds every module into its folder (``femkit.solvers.petsc.names`` into
``femkit.solvers.petsc``); the modules of the root folder ``femkit/`` count one by one
(``femkit.cli``, ``femkit.errors``). An ``__init__.py`` importing its own subtree re-exports it
and is not an edge; a module importing its parent package, or a sibling folder, is.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: A string naming a module for importlib: ``"pkg.mod"`` or ``"pkg.mod:attr"``.
MODULE_STRING = re.compile(r"^(?P<module>[A-Za-z_]\w*(?:\.\w+)+)(?::[\w.]+)?$")


def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _import_nodes(tree: ast.AST):
    """Every Import / ImportFrom node and string constant, skipping ``if TYPE_CHECKING:`` bodies."""
    stack = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            yield node
        elif isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend(node.orelse)
            continue
        stack.extend(ast.iter_child_nodes(node))


def _targets(node: ast.AST, here: list[str], files) -> list[str]:
    """The dotted names ``node`` imports (``here``: the package a relative import starts from)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    if isinstance(node, ast.Constant):
        match = MODULE_STRING.match(node.value)
        return [match["module"]] if match and match["module"] in files else []
    if node.level:
        base = here[: len(here) - node.level + 1]
        mod = ".".join(base + ([node.module] if node.module else []))
    else:
        mod = node.module or ""
    return [f"{mod}.{a.name}" if f"{mod}.{a.name}" in files else mod for a in node.names]


def import_graph(root: Path, package: str) -> dict[str, set[str]]:
    """``{module: {modules it imports}}`` over the modules of ``root/package``."""
    files = {_module_name(p, root): p for p in sorted((root / package).rglob("*.py"))}
    graph: dict[str, set[str]] = {name: set() for name in files}
    for name, path in files.items():
        is_pkg = path.name == "__init__.py"
        here = name.split(".") if is_pkg else name.split(".")[:-1]
        for node in _import_nodes(ast.parse(path.read_text(encoding="utf-8"))):
            targets = _targets(node, here, files)
            if isinstance(node, ast.Constant) and targets == [name]:
                continue  # a module naming itself (femkit.plugins: its entry-point group)
            for target in targets:
                while target and target not in files:  # import a.b.c of a non-module attribute
                    target = target.rpartition(".")[0]
                if target:
                    graph[name].add(target)
    return graph


def package_of(module: str, packages: set[str], root: str) -> str:
    """The folder ``module`` lives in (itself for a package's ``__init__``); ``root``'s own
    modules are their own nodes."""
    if module in packages:
        return module
    folder = module.rpartition(".")[0]
    return module if folder == root else folder


def package_graph(graph: dict[str, set[str]], packages: set[str], root: str) -> dict[str, set[str]]:
    """Fold ``graph`` into folders: ``{package: {packages its modules import}}``, without an
    ``__init__``'s imports of its own subtree and without a package's edges to itself."""
    out: dict[str, set[str]] = {}
    for module, imported in graph.items():
        src = package_of(module, packages, root)
        edges = out.setdefault(src, set())
        for target in imported:
            if module in packages and target.startswith(module + "."):
                continue  # a re-export from the package's own subtree
            dst = package_of(target, packages, root)
            if dst != src:
                edges.add(dst)
    return out


def femkit_graphs() -> tuple[dict[str, set[str]], dict[str, set[str]]]:
    """femkit's module graph and its package graph."""
    graph = import_graph(ROOT, "femkit")
    packages = {_module_name(p, ROOT) for p in (ROOT / "femkit").rglob("__init__.py")}
    return graph, package_graph(graph, packages, "femkit")


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with a cycle (Tarjan's algorithm, iterative), sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    out: list[list[str]] = []
    counter = 0
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == node:
                        break
                if len(comp) > 1 or node in graph.get(node, ()):
                    out.append(sorted(comp))
    return sorted(out)


def _explain(found: list[list[str]], graph: dict[str, set[str]]) -> str:
    """Each component with its edges, so a failure says which import to move."""
    lines = []
    for comp in found:
        lines.append(" <-> ".join(comp))
        lines += [f"    {a} -> {b}" for a in comp for b in sorted(graph[a] & set(comp))]
    return "\n".join(lines)


def test_no_import_cycles_between_femkit_modules():
    graph, _ = femkit_graphs()
    assert len(graph) > 100 and "femkit.cost.plan" in graph
    found = cycles(graph)
    assert not found, "import cycles (strongly connected components):\n" + _explain(found, graph)


def test_no_import_cycles_between_femkit_packages():
    """Folder granularity: a folder's modules may import each other, but no two folders import
    each other, directly or round a loop (a module the parent and the child both need belongs in
    the child or in a leaf below both)."""
    _, packages = femkit_graphs()
    assert {"femkit.solvers", "femkit.solvers.petsc", "femkit.cli", "femkit"} <= packages.keys()
    found = cycles(packages)
    assert not found, "package cycles (strongly connected components):\n" + _explain(found, packages)


def _write(root: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)


def test_the_checker_finds_cycles_in_a_tiny_package(tmp_path):
    """A lazy three-module cycle through a relative import and a package, a self-import, a
    TYPE_CHECKING import (no cycle) and an acyclic chain."""
    _write(tmp_path, {
        "toy/__init__.py": "",
        "toy/a.py": "from .sub import b\n",
        "toy/sub/__init__.py": "",
        "toy/sub/b.py": "def f():\n    from ..c import thing\n    return thing\n",
        "toy/c.py": "import toy.a\nthing = 1\n",
        "toy/d.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .e import x\n",
        "toy/e.py": "from . import d\nx = 1\n",
        "toy/selfish.py": "def g():\n    from . import selfish\n",
        "toy/leaf.py": "from .c import thing\n",
    })
    graph = import_graph(tmp_path, "toy")
    assert graph["toy.sub.b"] == {"toy.c"} and graph["toy.a"] == {"toy.sub.b"}
    assert graph["toy.d"] == set()
    assert cycles(graph) == [["toy.a", "toy.c", "toy.sub.b"], ["toy.selfish"]]
    graph["toy.c"].discard("toy.a")
    graph["toy.selfish"].clear()
    assert cycles(graph) == []


def test_the_package_graph_folds_folders_and_sees_string_imports(tmp_path):
    """Two folders that import each other through different modules (no module cycle) are a
    package cycle; an ``__init__`` re-exporting its subtree is not an edge; the root folder's
    modules are nodes of their own; an importlib string is an edge, a module's own name is not."""
    _write(tmp_path, {
        "toy/__init__.py": "from .low import base\n",
        "toy/cli.py": "import importlib\ndef main():\n    importlib.import_module('toy.app.run')\n",
        "toy/leaf.py": "NAME = 'toy.leaf'\n",
        "toy/low/__init__.py": "from .base import thing\n",
        "toy/low/base.py": "thing = 1\n",
        "toy/low/helper.py": "from ..high import user\n",
        "toy/high/__init__.py": "",
        "toy/high/user.py": "from ..low.base import thing\n",
        "toy/app/__init__.py": "",
        "toy/app/run.py": "X = 'toy.cli:main'\n",
    })
    graph = import_graph(tmp_path, "toy")
    assert graph["toy.cli"] == {"toy.app.run"} and graph["toy.leaf"] == set()
    assert cycles(graph) == [["toy.app.run", "toy.cli"]]
    packages = {"toy", "toy.low", "toy.high", "toy.app"}
    folded = package_graph(graph, packages, "toy")
    assert folded["toy"] == set() and folded["toy.low"] == {"toy.high"}
    assert folded["toy.high"] == {"toy.low"} and folded["toy.app"] == {"toy.cli"}
    assert cycles(folded) == [["toy.app", "toy.cli"], ["toy.high", "toy.low"]]
    graph["toy.low.helper"].clear()
    graph["toy.app.run"].clear()
    assert cycles(package_graph(graph, packages, "toy")) == []
