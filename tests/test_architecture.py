"""The layering of femkit, checked from the source: library layers never reach the application.

Layers: ``mesh -> fem -> solvers <- dynamics`` (and ``solids``, elastic bodies, beside dynamics:
neither imports the other; the elastic force takes a body object, and the compiled element
kernels both use live below both in ``elements``) know nothing of files; ``case``
(case and scene files), ``study`` and ``cli`` sit on top. ``cost/`` is a base of pure functions
of numbers below the application: it imports only the shared leaves, and the library never
imports it (the application plans and guards). Every import is read from the AST of every module,
imports inside functions (lazy ones) and strings naming a femkit module for importlib
(``"femkit.x.y"``, ``"femkit.x.y:attr"``) included. Import cycles, between modules and between
packages: ``tests/test_no_import_cycles.py``.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "femkit"
LIBRARY = ("mesh", "fem", "solvers", "dynamics", "solids", "elements", "contact")
APPLICATION = ("case", "study", "cli")
#: What the library must never import: the application and the cost model (planned above it).
ABOVE_THE_LIBRARY = APPLICATION + ("cost",)
#: Shared leaves any layer may import; they import only one another.
LEAVES = ("errors", "registry", "timing", "validation", "_version", "progress", "interrupt",
          "codegen", "kinds", "plugins")


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


#: A string naming a femkit module for importlib: ``"femkit.x.y"`` or ``"femkit.x.y:attr"``.
MODULE_STRING = re.compile(r"^(femkit(?:\.\w+)+)(?::[\w.]+)?$")


def _imports_of(source: str, package: list[str]) -> set[str]:
    """Absolute names of every femkit module ``source`` imports, anywhere in it, with
    relative imports resolved against ``package`` (e.g. ``["femkit", "dynamics"]``), and of
    every femkit module a string constant names (an import through importlib)."""
    out = set()
    for mod, names in _import_statements(source, package):
        out.add(mod)
        out |= {f"{mod}.{n}" for n in names}
    out |= {m[1] for node in ast.walk(ast.parse(source))
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and (m := MODULE_STRING.match(node.value))}
    return {m for m in out if m == "femkit" or m.startswith("femkit.")}


def _imported(path: Path) -> set[str]:
    rel = path.relative_to(PKG.parent).with_suffix("")
    return _imports_of(path.read_text(encoding="utf-8"), list(rel.parts[:-1]))


def _forbidden(names: set[str], layers) -> list[str]:
    return sorted(n for n in names for layer in layers
                  if n == f"femkit.{layer}" or n.startswith(f"femkit.{layer}."))


@pytest.mark.parametrize("layer", LIBRARY)
def test_library_layers_never_import_the_application_or_cost(layer):
    """No import from mesh/, fem/, solvers/, dynamics/ into cost/, case/, study/ or cli."""
    files = _modules(layer)
    assert len(files) >= 2 and any(p.name != "__init__.py" for p in files)
    bad = {str(p.relative_to(PKG)): _forbidden(_imported(p), ABOVE_THE_LIBRARY) for p in files}
    assert not {k: v for k, v in bad.items() if v}


def _outside(names: set[str], allowed) -> list[str]:
    """The femkit modules in ``names`` that are not ``femkit.<a>`` or below it for ``a`` in
    ``allowed``."""
    return sorted(n for n in names if not any(n == f"femkit.{a}" or n.startswith(f"femkit.{a}.")
                                              for a in allowed))


def test_cost_imports_no_library_or_application_module():
    """cost/ is a base: sizes in, seconds and bytes out; it imports only the shared leaves."""
    files = _modules("cost")
    assert len(files) > 3
    bad = {str(p.relative_to(PKG)): _outside(_imported(p), LEAVES + ("cost",)) for p in files}
    assert not {k: v for k, v in bad.items() if v}


def test_shared_leaves_import_only_leaves():
    """The leaves sit below every layer (cost included): a leaf importing a layer would put that
    layer under everything that uses the leaf."""
    files = [PKG / f"{leaf}.py" for leaf in LEAVES]
    assert all(p.is_file() for p in files)
    bad = {p.name: _outside(_imported(p), LEAVES) for p in files}
    assert not {k: v for k, v in bad.items() if v}


@pytest.mark.parametrize("layer", LIBRARY)
def test_library_layers_do_not_write_femkit_files(layer):
    """femkit.io (atomic result directories, result.json/CSV writers, figures) is the
    application's; meshes are read and written by femkit.mesh itself."""
    bad = {str(p.relative_to(PKG)): _forbidden(_imported(p), ("io",)) for p in _modules(layer)}
    assert not {k: v for k, v in bad.items() if v}


@pytest.mark.parametrize("layer, below", [
    ("mesh", ("fem", "solvers", "dynamics", "solids", "elements", "contact")),
    ("solvers", ("mesh", "fem", "dynamics", "solids", "elements", "contact")),
    ("fem", ("dynamics", "solids", "contact")),
    ("solids", ("dynamics",)),
    ("dynamics", ("solids",)),
    ("elements", ("mesh", "fem", "solvers", "dynamics", "solids", "contact")),
    ("contact", ("fem", "solvers", "dynamics", "solids", "elements"))],
    ids=["mesh", "solvers", "fem", "solids", "dynamics", "elements", "contact"])
def test_lower_layers_do_not_import_higher_library_layers(layer, below):
    """Below means below: and dynamics and solids, side by side, import nothing of each other
    (what both need, the compiled element kernels, is femkit.elements)."""
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
    lazy_cost = _imports_of("def g():\n    from ..cost.budget import check_budget\n", ["femkit", "mesh"])
    assert _forbidden(lazy_cost, ABOVE_THE_LIBRARY) == ["femkit.cost.budget",
                                                        "femkit.cost.budget.check_budget"]
    in_cost = _imports_of("from ..errors import InputError\ndef h():\n    from ..mesh import generate\n",
                          ["femkit", "cost"])
    assert _outside(in_cost, LEAVES + ("cost",)) == ["femkit.mesh", "femkit.mesh.generate"]
    assert IMPORT_STRING.match("femkit.dynamics.scene:run_scene") is None
    assert IMPORT_STRING.match("femkit.case.scene.run:run_scene")
    by_string = _imports_of('import importlib\ndef k():\n    importlib.import_module("femkit.solids.body")\n'
                            'X = "femkit.study.kinds:thing"\nY = "femkit is fast"\n', ["femkit", "dynamics"])
    assert by_string == {"femkit.solids.body", "femkit.study.kinds"}


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


def _calls(tree: ast.AST) -> set[str]:
    """Dotted names called in ``tree`` (``meshio.write(...)`` -> ``"meshio.write"``)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            parts, f = [], node.func
            while isinstance(f, ast.Attribute):
                parts.append(f.attr)
                f = f.value
            if isinstance(f, ast.Name):
                out.add(".".join([f.id] + parts[::-1]))
    return out


def _modules_where(predicate) -> list[str]:
    return sorted(str(p.relative_to(PKG)) for p in PKG.rglob("*.py")
                  if predicate(ast.parse(p.read_text(encoding="utf-8"))))


def test_one_vtk_writer():
    """meshio's writer is called in one place: femkit.mesh.vtk.write_cells."""
    assert _modules_where(lambda t: _calls(t) & {"meshio.write", "meshio.Mesh"}) == ["mesh/vtk.py"]


def test_one_scikit_fem_reference():
    """scikit-fem is imported by one module: the reference of femkit check and the studies."""
    def imports_skfem(tree):
        return any(isinstance(n, (ast.Import, ast.ImportFrom)) and any(
            (getattr(n, "module", None) or a.name).split(".")[0] == "skfem" for a in n.names)
            for n in ast.walk(tree))
    assert _modules_where(imports_skfem) == ["case/poisson/reference.py"]


def test_one_stage_timer():
    """No module keeps its own ``perf_counter`` stage table: stage timing is timing.StageTimer."""
    def times_stages(tree):
        for fn in ast.walk(tree):
            if isinstance(fn, ast.FunctionDef) and any(
                    "contextmanager" in ast.unparse(d) for d in fn.decorator_list):
                if "perf_counter" in ast.unparse(fn):
                    return True
        return False
    assert _modules_where(times_stages) == ["timing.py"]


def test_one_progress_interface():
    """Progress classes and progress iterators live in femkit/progress.py only."""
    def defines_progress(tree):
        return any(isinstance(n, (ast.ClassDef, ast.FunctionDef)) and "progress" in n.name.lower()
                   for n in ast.walk(tree))
    assert _modules_where(defines_progress) == ["progress.py"]
