"""No import cycles between femkit modules, lazy imports included.

The module import graph is read from the AST of every module: an edge ``a -> b`` for every
``import`` or ``from ... import`` in ``a`` (at module level or inside a function), ``b`` being
the module named (``from pkg import name`` names the submodule ``pkg.name`` when there is one,
else the package ``pkg``). Imports under ``if TYPE_CHECKING:`` never run and are left out. A
cycle is a strongly connected component of more than one module (Tarjan 1972), or a module
importing itself; the test lists every component, so one run shows every cycle to break.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _import_nodes(tree: ast.AST):
    """Every Import / ImportFrom node, skipping the bodies of ``if TYPE_CHECKING:``."""
    stack = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend(node.orelse)
            continue
        stack.extend(ast.iter_child_nodes(node))


def import_graph(root: Path, package: str) -> dict[str, set[str]]:
    """``{module: {modules it imports}}`` over the modules of ``root/package``."""
    files = {_module_name(p, root): p for p in sorted((root / package).rglob("*.py"))}
    graph: dict[str, set[str]] = {name: set() for name in files}
    for name, path in files.items():
        is_pkg = path.name == "__init__.py"
        here = name.split(".") if is_pkg else name.split(".")[:-1]
        for node in _import_nodes(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                if node.level:
                    base = here[: len(here) - node.level + 1]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in files else mod
                           for a in node.names]
            for target in targets:
                while target and target not in files:  # import a.b.c of a non-module attribute
                    target = target.rpartition(".")[0]
                if target:
                    graph[name].add(target)
    return graph


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


def test_no_import_cycles_between_femkit_modules():
    graph = import_graph(ROOT, "femkit")
    assert len(graph) > 100 and "femkit.cost.plan" in graph
    found = cycles(graph)
    assert not found, "import cycles (strongly connected components):\n" + "\n".join(
        " <-> ".join(c) for c in found)


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
