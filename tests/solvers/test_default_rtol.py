"""The default ``rtol`` has one home, :data:`femkit.solvers.core.defaults.DEFAULT_RTOL`: changing it
there changes it for the Python API, case files, scene files and study files alike.

Each route is tested with the default patched to a value no file or signature names
(``PATCHED``); the solves then stop at ``PATCHED * ||b||`` (a test that fails whenever some
route keeps a default of its own).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import yaml

import femkit
from femkit.solvers import SolverSpec, defaults, solve

PATCHED = 3.7e-7


@pytest.fixture
def patched(monkeypatch):
    monkeypatch.setattr(defaults, "DEFAULT_RTOL", PATCHED)
    return PATCHED


def _laplacian(n=30):
    return sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n), format="csr")


@pytest.mark.parametrize("method", ["cg", "pcg", "jacobi", "direct",
                                    pytest.param("cholesky", marks=pytest.mark.cholmod)])
def test_python_api_solve_stops_at_the_patched_default(patched, method):
    b = np.linspace(1.0, 2.0, 30)
    res = solve(_laplacian(), b, method=method, maxiter=100000)
    assert res.tolerance == pytest.approx(patched * np.linalg.norm(b), rel=1e-12)


@pytest.mark.parametrize("make", [lambda: SolverSpec("cg"), lambda: SolverSpec.from_mapping({}),
                                  lambda: SolverSpec.from_mapping({"method": "direct"})],
                         ids=["constructor", "from_mapping", "from_mapping_direct"])
def test_solver_specs_take_the_patched_default(patched, make):
    assert make().rtol == patched


def _write(path, data):
    path.write_text(yaml.safe_dump(data))
    return path


def test_a_case_file_without_rtol_solves_to_the_patched_default(patched, tmp_path):
    case = {"problem": "poisson", "name": "rtol_default", "mesh": {"geometry": "unit_square", "h": 0.25},
            "source": "1", "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
            "solver": {"method": "cg"}}
    c = femkit.load_case(_write(tmp_path / "case.yaml", case))
    assert c.solver.rtol == patched
    res = c.run(write=False, quiet=True).solve
    assert res.converged and res.tolerance == pytest.approx(
        patched * res.residuals[0], rel=1e-12)   # x0 = 0: the first residual is ||b||


def test_a_scene_file_without_rtol_steps_with_the_patched_default(patched, tmp_path):
    from femkit.case.scene.run import build_context

    scene = {"problem": "mass_spring", "name": "rtol_default",
             "system": {"type": "single_spring", "k": 100.0, "m": 1.0},
             "integrator": {"method": "implicit_euler"}, "linear_solver": {"method": "cg"},
             "dt": 0.01, "t_end": 0.02}
    c = femkit.load_case(_write(tmp_path / "scene.yaml", scene))
    assert c.solver.rtol == patched
    assert build_context(c).session.spec.rtol == patched


def test_a_study_file_without_rtol_and_the_study_default_take_the_patched_default(patched, tmp_path):
    from femkit.study.load import load_study

    study = {"kind": "poisson_convergence",
             "problem": {"mesh": {"geometry": "unit_square"}, "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
                         "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
                         "exact": {"u": "sin(pi*x)*sin(pi*y)",
                                   "grad": ["pi*cos(pi*x)*sin(pi*y)", "pi*sin(pi*x)*cos(pi*y)"]}},
             "levels": {"h0": 0.5, "count": 2}}
    default = load_study(_write(tmp_path / "default.yaml", study))
    assert [s.rtol for s in default.solvers] == [patched]
    named = load_study(_write(tmp_path / "named.yaml", {**study, "solvers": [{"method": "cg"}]}))
    assert [s.rtol for s in named.solvers] == [patched]


def _bound_defaults() -> list[str]:
    """Every signature in femkit that binds a default at import: a name of
    :mod:`femkit.solvers.core.defaults` as a default value, or an ``rtol`` / ``atol`` parameter
    (or dataclass field) whose default is anything but None (a literal copy of a default)."""
    import ast
    from pathlib import Path

    names = {n for n in vars(defaults) if n.isupper()}
    found = []
    for path in sorted(Path(femkit.__file__).parent.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            where = f"{path.name}:{getattr(node, 'lineno', 0)}"
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
                a = node.args
                positional = a.posonlyargs + a.args
                pairs = list(zip(positional[len(positional) - len(a.defaults):], a.defaults))
                pairs += [(k, d) for k, d in zip(a.kwonlyargs, a.kw_defaults) if d is not None]
                for arg, d in pairs:
                    named = getattr(d, "id", getattr(d, "attr", None)) in names
                    literal = arg.arg in ("rtol", "atol") and not (
                        isinstance(d, ast.Constant) and d.value is None)
                    if named or literal:
                        found.append(f"{where} {arg.arg}={ast.unparse(d)}")
            elif (isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name)
                  and node.target.id in ("rtol", "atol") and isinstance(node.value, ast.Constant)):
                found.append(f"{where} field {node.target.id} = {ast.unparse(node.value)}")
    return found


def test_no_signature_binds_a_default_at_import():
    """A default bound into a signature (``rtol=DEFAULT_RTOL``, ``rtol=1e-10``) would keep the
    old value when :mod:`femkit.solvers.core.defaults` changes: every one reads it at the call
    (``rtol=None``)."""
    assert _bound_defaults() == []


@pytest.mark.parametrize("method", ["cg", "pcg", "jacobi", "steepest_descent", "direct"])
def test_each_method_called_directly_stops_at_the_patched_default(patched, method):
    """Not only :func:`solve`: each method's own function reads the default at the call."""
    import femkit.solvers as solvers

    n = 31
    A = _laplacian(n)
    b = np.linspace(1.0, 2.0, n)
    fn = getattr(solvers, method)
    res = fn(A, b, maxiter=100000)
    assert res.tolerance == pytest.approx(patched * np.linalg.norm(b), rel=1e-12)


def test_the_newton_default_is_read_when_used(monkeypatch):
    """The Newton tolerance of a static solid has one home too: a solid file's ``static`` block
    without ``rtol`` and :func:`femkit.solids.solve_static` read it when used."""
    import inspect

    from femkit.case.solid.spec import StaticSpec
    from femkit.solids import solve_static

    monkeypatch.setattr(defaults, "NEWTON_RTOL", 2.5e-9)
    assert StaticSpec().rtol == 2.5e-9
    assert inspect.signature(solve_static).parameters["rtol"].default is None
