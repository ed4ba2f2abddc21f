"""``femkit warmup`` generates and compiles the built-in materials' kernels: afterwards a fresh
process evaluates a body from the cache -- numba loads every kernel it calls (no compile) and
SymPy is never imported; and a bundled solid case then runs through the command in that cache
(the first thing a newcomer does after the README's first command)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

PROBE = """
import json, sys
import numpy as np
from femkit.solids import ElasticBody, material
X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
mat = material("stvk", mu=1.0, lam=2.0)
ElasticBody(X, [[0, 1, 2, 3]], mat).evaluate(1.2 * X, 2, project=True)
p2 = ElasticBody(X, [[0, 1, 2, 3]], mat, element="P2")
p2.evaluate(1.2 * p2.rest_positions, 2, project=True)
mod = mat.kernels()
out = {}
for name in ("element_pass", "element_pass_points"):
    stats = getattr(mod, name).stats
    out[name] = [sum(stats.cache_hits.values()), sum(stats.cache_misses.values())]
out["sympy"] = "sympy" in sys.modules
print(json.dumps(out))
"""


@pytest.mark.slow
@pytest.mark.xdist_group("fresh_warmup")
def test_warmup_compiles_the_builtin_materials_once(tmp_path, fresh_warmup):
    """The session's one ``femkit warmup`` into an empty femkit cache (:func:`fresh_warmup`,
    shared with the Poisson warm-up's tests)."""
    from femkit.solids.warmup import warm_up  # noqa: F401  (importable without side effects)

    cache, _, env = fresh_warmup
    assert list((cache / "energies").glob("femkit_energy_*.py"))
    probe = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True,
                           timeout=600)
    assert probe.returncode == 0, probe.stderr
    out = json.loads(probe.stdout.strip().splitlines()[-1])
    # [cache hits, misses]: P1's pass and P2's pass at quadrature points both loaded, none compiled
    assert out == {"element_pass": [1, 0], "element_pass_points": [1, 0], "sympy": False}

    # a newcomer's next step: a bundled solid case through the command, in the same fresh cache
    case = Path(__file__).resolve().parents[2] / "cases" / "solid_cantilever.yaml"
    solve = subprocess.run([sys.executable, "-m", "femkit", "solve", str(case), "--output",
                            str(tmp_path / "out")], env=env, capture_output=True, text=True,
                           timeout=900)
    assert solve.returncode == 0, solve.stderr
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["verdict"] == "converged"
