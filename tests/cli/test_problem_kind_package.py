"""A new problem kind is ONE package: written here into a temporary plugin directory (nothing in
femkit edited), loaded through ``FEMKIT_PLUGINS`` and run by ``femkit solve`` (a subprocess),
``femkit solve --dry-run`` (its plan, and the budget refusal the plan leads to), ``femkit list``
and the schema (a misspelt key refused in one line naming the valid keys).

The package ``heatbar`` owns everything about its kind, as the built-in kinds do (docs/
architecture.md, "a problem kind"): ``kind.py`` the registration, ``schema.py``, ``spec.py`` (the
frozen spec holding the solver), ``cost.py`` (the plan), ``run.py`` (prepare, run) and
``result.py`` (its result, a :class:`femkit.case.result.RunResult`). Its numbers can fail: P1 on
``-k u'' = q`` with fixed end temperatures is exact at the nodes (the exact solution's second
derivative is constant), so the written ``max_nodal_error`` is rounding only, and the plan's
seconds (``1e-5 n``) make ``n: 1e9`` exceed the default one-hour budget.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helper
from _plugins import run_with_plugins, write_yaml  # noqa: E402

PACKAGE = {
    "__init__.py": '''
        """``problem: heatbar``: steady heat conduction in a bar, -k u'' = q on (0, 1), P1."""
        from . import kind  # noqa: F401  registers the kind
    ''',
    "kind.py": '''
        """``problem: heatbar``: steady heat conduction in a bar by P1 elements."""
        from femkit.kinds import Kind, register_kind

        from .cost import plan
        from .run import prepare, run
        from .schema import SCHEMA

        KIND = register_kind(Kind("heatbar", "problem", SCHEMA, prepare, run, plan,
                                  default_solver="cg"))
    ''',
    "schema.py": '''
        from femkit.case.specs import SOLVER_SCHEMA

        SCHEMA = {"type": "object", "additionalProperties": False, "required": ["problem", "n"],
                  "properties": {"problem": {"const": "heatbar"}, "name": {"type": "string"},
                                 "n": {"type": "integer", "minimum": 2},
                                 "k": {"type": "number", "exclusiveMinimum": 0, "default": 1.0},
                                 "q": {"type": "number", "default": 1.0},
                                 "ends": {"type": "array", "items": {"type": "number"},
                                          "minItems": 2, "maxItems": 2, "default": [0.0, 0.0]},
                                 "solver": {**SOLVER_SCHEMA, "default": {}},
                                 "output": {"type": "string", "default": "out"}}}
    ''',
    "spec.py": '''
        from dataclasses import dataclass
        from typing import Any


        @dataclass(frozen=True)
        class HeatSpec:
            n: int
            k: float
            q: float
            ends: tuple
            solver: Any
            output: str
    ''',
    "cost.py": '''
        from femkit.cost import Plan, Stage


        def plan(case, measure=True):
            n = case.spec.n
            return Plan("heatbar", f"{case.name}: {n:,} elements",
                        {"elements": n}, [Stage("solve", 1e-5 * n, 1e6, 0.0, "tridiagonal")],
                        assumptions=["1e-5 s per element"])
    ''',
    "result.py": '''
        from dataclasses import dataclass, field
        from typing import Any

        import numpy as np

        from femkit.case.result import RunResult


        @dataclass
        class HeatResult(RunResult):
            case: Any
            u: np.ndarray
            solve: Any
            max_nodal_error: float
            timings: dict = field(default_factory=dict)
            files: list = field(default_factory=list)
            output_dir: Any = None

            @property
            def converged(self):
                return bool(self.solve.converged)

            def facts(self):
                return {"n": self.case.spec.n, "max_nodal_error": self.max_nodal_error,
                        "solver": self.case.spec.solver.method, "converged": self.converged}

            def summary_lines(self):
                lines = [f"heatbar   {self.case.name}: max nodal error {self.max_nodal_error:.3e}",
                         self.timings_line()]
                return lines + ([self.output_line()] if self.output_dir is not None else [])
    ''',
    "run.py": '''
        """``problem: heatbar``: steady heat conduction in a bar, -k u'' = q, P1 elements."""
        import time

        import numpy as np
        import scipy.sparse as sp

        from femkit.case.specs import solver_spec
        from femkit.io.atomic import EARLIER_RUN, atomic_directory
        from femkit.kinds import KINDS

        from .result import HeatResult
        from .spec import HeatSpec


        def prepare(case):
            d = case.data
            default = KINDS.get(case.problem, "problem").default_solver
            case.spec = HeatSpec(int(d["n"]), float(d["k"]), float(d["q"]), tuple(d["ends"]),
                                 solver_spec(d["solver"], "solver", default_method=default),
                                 str(case.base_dir / d["output"]))


        def run(case, output_dir=None, quiet=False, write=True, echo=None):
            s = case.spec
            t0 = time.perf_counter()
            n, h = s.n, 1.0 / s.n
            x = np.linspace(0.0, 1.0, n + 1)
            a, b = s.ends
            A = sp.diags([-np.ones(n - 2), 2 * np.ones(n - 1), -np.ones(n - 2)], [-1, 0, 1]).tocsr()
            rhs = np.full(n - 1, s.q * h * h / s.k)
            rhs[0] += a
            rhs[-1] += b
            res = s.solver.solve(A, rhs)
            u = np.concatenate([[a], res.x, [b]])
            exact = a + (b - a) * x + s.q * x * (1 - x) / (2 * s.k)
            result = HeatResult(case, u, res, float(np.max(np.abs(u - exact))),
                                timings={"solve": time.perf_counter() - t0})
            if write:
                final = output_dir or s.output
                with atomic_directory(final, EARLIER_RUN) as tmp:
                    np.savetxt(tmp / "u.txt", u)
                    result.write_result_json(tmp, ["u.txt", "result.json"])
                result.output_dir = final
            if not quiet:
                for line in result.summary_lines():
                    (echo or print)(line)
            return result
    ''',
}


def _femkit(tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    plugins = tmp_path / "plugins"
    if not plugins.exists():
        (plugins / "heatbar").mkdir(parents=True)
        for name, text in PACKAGE.items():
            (plugins / "heatbar" / name).write_text(textwrap.dedent(text).lstrip())
    return run_with_plugins(tmp_path, plugins, "heatbar", *args)


_case = write_yaml


def test_a_problem_kind_package_runs_through_femkit_solve(tmp_path):
    case = _case(tmp_path, "bar.yaml", "problem: heatbar\nn: 40\nk: 2.0\nq: 3.0\nends: [1.0, -0.5]\n"
                                       "solver: {rtol: 1.0e-13}\n")
    p = _femkit(tmp_path, "solve", case)
    assert p.returncode == 0, p.stderr
    assert "heatbar   bar: max nodal error" in p.stdout
    data = json.loads((tmp_path / "out" / "result.json").read_text())
    # the base type's header, then the kind's facts
    assert list(data)[:4] == ["case", "problem", "case_file", "femkit_version"]
    assert (data["case"], data["problem"], data["n"]) == ("bar", "heatbar", 40)
    assert data["solver"] == "cg"  # the kind's declared default (the file names no method)
    assert data["converged"] is True and data["max_nodal_error"] < 1e-11
    u = [float(v) for v in (tmp_path / "out" / "u.txt").read_text().split()]
    assert len(u) == 41 and (u[0], u[-1]) == (1.0, -0.5)
    assert abs(u[20] - (0.25 + 3.0 * 0.25 / 4.0)) < 1e-11  # u(1/2) = 1/4 + q/(8k)


def test_a_problem_kind_package_is_planned_listed_and_schema_checked(tmp_path):
    small = _case(tmp_path, "small.yaml", "problem: heatbar\nn: 1000\n")
    p = _femkit(tmp_path, "solve", small, "--dry-run")
    assert p.returncode == 0, p.stderr
    assert "small: 1,000 elements" in p.stdout and "tridiagonal" in p.stdout
    assert not (tmp_path / "out").exists()  # a dry run writes nothing

    huge = _case(tmp_path, "huge.yaml", "problem: heatbar\nn: 1000000000\n")  # 1e4 s > 1 hour
    p = _femkit(tmp_path, "solve", huge, "--dry-run")
    assert p.returncode == 2 and "time" in p.stderr, (p.stdout, p.stderr)
    p = _femkit(tmp_path, "solve", huge)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, p.stderr
    assert not (tmp_path / "out").exists()

    listed = _femkit(tmp_path, "list", "problems")
    assert listed.returncode == 0, listed.stderr
    line = next(ln for ln in listed.stdout.splitlines() if "heatbar" in ln)
    assert "steady heat conduction in a bar" in line

    typo = _case(tmp_path, "typo.yaml", "problem: heatbar\nn: 10\nkappa: 2\n")
    p = _femkit(tmp_path, "solve", typo)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, p.stderr
    assert "kappa" in p.stderr and "ends" in p.stderr  # the misspelt key and the valid ones
    assert "Traceback" not in p.stderr
