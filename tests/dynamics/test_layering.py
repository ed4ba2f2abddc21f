"""femkit.dynamics is a library layer: no module in it imports the application layer (case,
study, io, cli), not even lazily inside a function, and none resolves names through importlib."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "femkit" / "dynamics"
UPPER = ("femkit.case", "femkit.study", "femkit.io", "femkit.cli")
MODULES = sorted(PACKAGE.rglob("*.py"))


def imported(path: Path) -> set[str]:
    """Absolute names of every module ``path`` imports (relative imports resolved)."""
    package = ["femkit", *path.relative_to(PACKAGE.parent).with_suffix("").parts[:-1]]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            mod = ".".join(base + ([node.module] if node.module else []))
            out.add(mod)
            out.update(f"{mod}.{a.name}" for a in node.names)
    return out


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_dynamics_imports_no_application_layer(path):
    names = imported(path)
    upward = sorted(n for n in names if n.startswith(UPPER) or n in ("femkit", "femkit.__init__"))
    assert not upward, f"{path.name} imports the application layer: {upward}"
    assert "importlib" not in names, f"{path.name} resolves modules by name (importlib)"


def test_every_dynamics_module_is_checked():
    assert len(MODULES) > 30 and PACKAGE / "integrators" / "runge_kutta.py" in MODULES
