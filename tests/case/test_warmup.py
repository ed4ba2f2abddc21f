"""The first run after an install compiles the kernels in its own ``compile`` stage, saying so;
``femkit warmup`` does it ahead; a warm cache compiles nothing."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

CASE = {
    "problem": "poisson",
    "mesh": {"geometry": "unit_square", "h": 0.25, "refine": 1},
    "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
    "solver": {"method": "fmg"},
    "output": {"dir": "out", "vtu": False},
}


def _run(args, cwd, cache=None):
    env = dict(os.environ, **({} if cache is None else {"NUMBA_CACHE_DIR": str(cache)}))
    proc = subprocess.run([sys.executable, "-m", "femkit.cli", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


@pytest.fixture(scope="module")
def triangle_warmup(tmp_path_factory):
    """An empty numba cache after a warm-up without multigrid on triangles (what a first pcg +
    jacobi run compiles): ``(cache, the warm-up's output lines)``. Its tests (one worker:
    ``xdist_group("triangle_warmup")``) share the compile; only the multigrid run adds to it."""
    cache = tmp_path_factory.mktemp("numba-cache")
    probe = ("from femkit.case.poisson.warmup import warm_up, kernels_cached, families; "
             "warm_up(print, multigrid=False, dims=(2,)); "
             "print(kernels_cached(families(False), (2,)), "
             "kernels_cached(('geometric multigrid',), (2,)))")
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         env=dict(os.environ, NUMBA_CACHE_DIR=str(cache)), timeout=900)
    assert res.returncode == 0, res.stderr
    return cache, res.stdout.strip().splitlines()


@pytest.mark.slow
@pytest.mark.xdist_group("triangle_warmup")
def test_first_run_compiles_in_its_own_stage_then_never_again(tmp_path, triangle_warmup):
    """A compile cache without the multigrid kernels (a fresh install, after a run without
    multigrid: :func:`triangle_warmup`): the first fmg run says it compiles and books a
    ``compile`` stage; the second run of the same case has neither."""
    (tmp_path / "case.yaml").write_text(yaml.safe_dump(CASE))
    cache, _ = triangle_warmup
    first = _run(["solve", "case.yaml"], tmp_path, cache)
    timings = json.loads((tmp_path / "out" / "result.json").read_text())["timings"]
    assert ("compiling kernels (first run, cached afterwards): mesh passes, P1 assembly, "
            "solver checks, geometric multigrid, error estimate..." in first)
    assert "compiled in " in first
    assert timings["compile"] > 0 and list(timings)[:3] == ["numba", "compile", "mesh"]
    second = _run(["solve", "case.yaml"], tmp_path, cache)
    assert "compiling" not in second
    assert "compile" not in json.loads((tmp_path / "out" / "result.json").read_text())["timings"]
    # a case on triangles compiled the triangle run's kernels, not the tetrahedra's
    probe = ("from femkit.case.poisson.warmup import kernels_cached as k, families as f; "
             "print(k(f(True), (2,)), k(f(True), (2, 3)))")
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         env=dict(os.environ, NUMBA_CACHE_DIR=str(cache)))
    assert res.stdout.strip() == "True False", res.stderr


@pytest.mark.xdist_group("fresh_warmup")
def test_warmup_fills_the_cache(tmp_path, fresh_warmup):
    """``femkit warmup`` with the package's own cache (compiled once, loaded afterwards); an
    empty cache directory is seen as empty. (The session's one warm-up into an empty femkit
    cache, :func:`fresh_warmup`: the expressions found there were compiled by it.)"""
    from femkit.case.poisson.warmup import COMPILE_MESSAGE

    _, out, env = fresh_warmup
    assert COMPILE_MESSAGE in out and "kernels ready in" in out
    probe = ("from femkit.case.poisson.warmup import kernels_cached; "
             "print(kernels_cached())")
    res = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True)
    assert res.stdout.strip() == "True"
    empty = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                           env=dict(env, NUMBA_CACHE_DIR=str(tmp_path / "other")))
    assert empty.stdout.strip() == "False"
    # the expressions of the bundled fmg case (the only bundled mesh large enough to compile them)
    fmg = ("from femkit.case import load_case; from femkit.case.compiled_expressions import "
           "case_kernels; from femkit.case.poisson.warmup import expressions_cached; "
           f"print(expressions_cached(case_kernels(load_case({str(FMG_CASE)!r})), 2))")
    res = subprocess.run([sys.executable, "-c", fmg], env=env, capture_output=True, text=True)
    assert res.stdout.strip() == "True", res.stderr


@pytest.mark.xdist_group("triangle_warmup")
def test_a_run_without_multigrid_compiles_no_multigrid_kernel(triangle_warmup):
    """The families a run needs: pcg + jacobi compiles edges and assembly, not multigrid (in an
    empty numba cache: :func:`triangle_warmup`)."""
    from femkit.case.poisson.warmup import families

    assert families(True) == ("mesh passes", "P1 assembly", "solver checks", "geometric multigrid",
                              "error estimate")
    assert families(False) == ("mesh passes", "P1 assembly", "solver checks", "error estimate")
    _, lines = triangle_warmup
    assert lines[0] == ("compiling kernels (first run, cached afterwards): mesh passes, "
                        "P1 assembly, solver checks, error estimate...")
    assert lines[-1] == "True False"


FMG_CASE = Path(__file__).resolve().parents[2] / "cases" / "poisson_fmg_unit_square.yaml"


def test_the_warm_up_case_compiles_the_bundled_fmg_cases_expressions():
    """Same trees, one generated module: what ``femkit warmup`` compiles is what the case runs."""
    from femkit.case import case_from_dict, load_case
    from femkit.case.compiled_expressions import case_kernels
    from femkit.case.poisson.warmup import _TINY

    tiny = case_kernels(case_from_dict(dict(_TINY)))
    assert case_kernels(load_case(FMG_CASE)).module is tiny.module


EXPRESSIONS_RUN = """
import sys
import femkit.fem.fused.kernels as k
from femkit.case import case_from_dict
k.NUMBA_THRESHOLD = 0          # this small mesh takes the compiled path, as a large one would
case = case_from_dict({case!r})
result = case.run(write=False, quiet=False)
print("timings", sorted(result.timings))
"""


@pytest.mark.slow
def test_first_use_of_new_expressions_compiles_in_the_compile_stage(tmp_path):
    """Expressions never compiled before: the run says so and books a ``compile`` stage before
    the mesh is used; the next process loads them from the cache (nothing said, no stage)."""
    from femkit.case.poisson.warmup import EXPRESSIONS_MESSAGE

    case = dict(CASE, solver={"method": "pcg", "preconditioner": "amg"},
                source="3*pi**2*sin(pi*x)*sin(pi*y) + 0.25",
                exact={"u": "1.5*sin(pi*x)*sin(pi*y)",
                       "grad": ["1.5*pi*cos(pi*x)*sin(pi*y)", "1.5*pi*sin(pi*x)*cos(pi*y)"]})
    # a fresh femkit cache: the generated expression module (and numba's code for it, cached
    # beside it) is new; the pipeline's own kernels come from the default cache as in any run
    # after the first (compiling them too would repeat test_first_run_compiles_..., ~20 s)
    env = dict(os.environ, FEMKIT_CACHE_DIR=str(tmp_path / "femkit"))
    outs = []
    for _ in range(2):
        proc = subprocess.run([sys.executable, "-c", EXPRESSIONS_RUN.format(case=case)], cwd=tmp_path,
                              env=env, capture_output=True, text=True, timeout=900)
        assert proc.returncode == 0, proc.stderr
        outs.append(proc.stdout)
    assert EXPRESSIONS_MESSAGE in outs[0] and "'compile'" in outs[0]
    assert "compiling" not in outs[1] and "'compile'" not in outs[1]
    assert list((tmp_path / "femkit" / "expressions").glob("femkit_expr_*.py"))


FIRST_3D_RUN = """
import importlib, sys
import numba
from femkit.case import case_from_dict
from femkit.case.poisson import warmup
for module, name in warmup._thresholds():   # the compiled paths a large tetrahedral mesh takes
    setattr(importlib.import_module(module), name, 0)
case = case_from_dict({case!r})
print("compile now:", warmup.must_compile(None, True))
case.run(write=False, quiet=True)
missed = sorted(f"{{mod}}.{{name}}" for mod, m in list(sys.modules.items()) if mod.startswith("femkit")
                for name, fn in vars(m).items()
                if isinstance(fn, numba.core.registry.CPUDispatcher) and fn.stats.cache_misses)
print("compiled:", missed)
"""


@pytest.mark.xdist_group("fresh_warmup")
def test_warmup_compiles_the_tetrahedral_kernels(tmp_path, fresh_warmup):
    """After ``femkit warmup`` a first run on tetrahedra (fmg, every compiled path taken) loads
    every kernel from the cache: none is compiled in the run, and none is missing from the
    families the run checks before it starts. The generated expression modules are in the
    session's fresh femkit cache (:func:`fresh_warmup`), so their passes were compiled by that
    warm-up, whatever the shared cache holds."""
    from femkit.case.poisson.warmup import _TINY_3D

    _, _, env = fresh_warmup
    case = dict(_TINY_3D, mesh={"geometry": "kuhn_cube", "h": 0.5, "refine": 2},
                solver={"method": "fmg"}, output={"vtu": False})
    proc = subprocess.run([sys.executable, "-c", FIRST_3D_RUN.format(case=case)], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr
    assert "compile now: False" in proc.stdout
    assert "compiled: []" in proc.stdout, proc.stdout


EXACTLY = """
import re, sys
import numba
from femkit.case.poisson import warmup
warmup.warm_up(None, multigrid={multigrid}, dims={dims})
compiled = sorted(f"{{mod}}.{{name}}" for mod, m in list(sys.modules.items())
                  if mod.startswith(("femkit.mesh", "femkit.fem", "femkit.solvers"))
                  for name, fn in vars(m).items()
                  if isinstance(fn, numba.core.registry.CPUDispatcher) and fn.__module__ == mod and fn.signatures)
print("compiled:", compiled)
registry = warmup._registry()
print("registered:", sorted(f"{{k.module}}.{{k.name}}" for k in registry.kernels(warmup.families({multigrid}))
                           if 3 in {dims} or not k.tetrahedra_only))
print("constants:", sorted(f"{{mod}}.{{name}}" for mod, m in list(sys.modules.items())
                           if mod.startswith(("femkit.mesh", "femkit.fem", "femkit.solvers"))
                           for name in vars(m) if re.fullmatch(r"\\w*NUMBA_(THRESHOLD\\w*|NNZ)", name)))
print("thresholds:", sorted(f"{{mod}}.{{name}}" for mod, name in warmup._thresholds()))
"""


@pytest.mark.parametrize("multigrid, dims", [(True, (2, 3)), (False, (2,))])
def test_the_warm_up_compiles_exactly_the_declared_kernels(multigrid, dims):
    """The kernels a warm-up compiles (or loads) are the ones the library modules declare
    (:mod:`femkit.warmup_registry`), no more and no fewer: a kernel added to a compiled path
    without its declaration would be compiled inside a first run's stages and never checked by
    :func:`~femkit.case.poisson.warmup.kernels_cached`. Every size constant of the pipeline's
    modules that chooses a compiled path is a declared threshold (the warm-up lowers it)."""
    proc = subprocess.run([sys.executable, "-c", EXACTLY.format(multigrid=multigrid, dims=dims)],
                          capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr
    lines = dict(line.split(": ", 1) for line in proc.stdout.splitlines() if ": " in line)
    compiled, registered = _printed_list(lines["compiled"]), _printed_list(lines["registered"])
    assert len(compiled) > 20 and compiled == registered
    assert _printed_list(lines["constants"]) == _printed_list(lines["thresholds"])


def _printed_list(text: str) -> list[str]:
    """A printed list of strings (``['a.b', 'c.d']``) read back without eval."""
    return json.loads(text.replace("'", '"'))
