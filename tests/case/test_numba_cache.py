"""femkit's cached kernels load without numba's compiler registries
(:mod:`femkit.numba_cache`) and give the same numbers; a function that is not femkit's, and any
function under a numba that was not checked, is loaded by numba as before."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

from femkit.numba_cache import CHECKED

#: A fmg case large enough for the compiled paths (mesh, assembly, elimination, multigrid, the
#: fused error and estimate passes): 263,169 nodes.
CASE = {
    "problem": "poisson",
    "mesh": {"geometry": "unit_square", "h": 0.125, "refine": 6},
    "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
    "exact": {"u": "sin(pi*x)*sin(pi*y)",
              "grad": ["pi*cos(pi*x)*sin(pi*y)", "pi*sin(pi*x)*cos(pi*y)"]},
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
    "estimator": "residual",
    "solver": {"method": "fmg"},
}

#: Counts numba's registry refreshes (``BaseContext.refresh``) in ``refreshed``.
COUNT = "; ".join(["refreshed = []", "refresh = numba.core.base.BaseContext.refresh",
                   "counted = lambda self: refreshed.append(1) or refresh(self)",
                   "numba.core.base.BaseContext.refresh = counted"])

#: Runs the case through the case layer's solve (which starts numba as the command does) in a
#: fresh interpreter, counting numba's registry refreshes; ``off``: as with a numba that was not
#: checked.
PROBE = textwrap.dedent("""
    import json, sys
    import numba.core.base, numba.core.registry
    import femkit.numba_cache as numba_cache
    if sys.argv[1] == "off":
        numba_cache.CHECKED = ()
    {COUNT}
    from femkit.case import case_from_dict
    result = case_from_dict(json.loads(sys.argv[2])).run(write=False, quiet=True)
    d = result.to_dict()
    misses = [n for m, mod in list(sys.modules.items()) if m.startswith("femkit")
              for n, fn in vars(mod).items()
              if isinstance(fn, numba.core.registry.CPUDispatcher) and fn.stats.cache_misses]
    print(json.dumps({"lean": numba_cache._INSTALLED, "registries": bool(refreshed),
                      "compiled": misses,
                      "errors": d["errors"], "estimate": d["error_estimate"],
                      "residual": d["solver"]["true_residual"]}))
""").replace("{COUNT}", COUNT)


def _probe(mode: str) -> dict:
    """The probe's report from a run that compiled nothing: the first run of a fresh cache
    compiles, and so may a run while another process rewrites a cache index (the suite's
    parallel workers); those runs are repeated."""
    for _ in range(3):
        proc = subprocess.run([sys.executable, "-c", PROBE, mode, json.dumps(CASE)],
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
        report = json.loads(proc.stdout.strip().splitlines()[-1])
        if not report["compiled"]:
            return report
    raise AssertionError(f"every run compiled kernels: {report['compiled']}")


def _installed_numba() -> str:
    import numba

    return ".".join(numba.__version__.split(".")[:2])


@pytest.mark.slow
def test_cached_kernels_load_without_the_registries_and_give_the_same_numbers():
    lean, full = _probe("on"), _probe("off")
    assert full["lean"] is False and full["registries"] is True
    if _installed_numba() in CHECKED:
        assert lean["lean"] is True
        assert lean["registries"] is False, "a cached kernel loaded numba's compiler registries"
    else:
        assert lean["lean"] is False
    for key in ("errors", "estimate", "residual"):
        assert lean[key] == full[key], key  # the same machine code: the same bits


FOREIGN = textwrap.dedent("""
    import sys
    import numba.core.base
    sys.path.insert(0, sys.argv[1])
    from femkit.numba_cache import lean_cache_loads
    lean_cache_loads()
    {COUNT}
    import foreign
    assert foreign.twice(21.0) == 42.0
    print(bool(refreshed))
""").replace("{COUNT}", COUNT)


def test_a_function_that_is_not_femkits_is_loaded_by_numba(tmp_path):
    """A user's cached function: numba loads its registries first, as without femkit."""
    (tmp_path / "foreign.py").write_text(
        "import numba\n\n@numba.njit(cache=True)\ndef twice(x):\n    return 2.0 * x\n")
    env_cache = {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    for _ in range(2):                     # compiled, then loaded from the cache
        proc = subprocess.run([sys.executable, "-c", FOREIGN, str(tmp_path)], text=True,
                              capture_output=True, env={**os.environ, **env_cache}, timeout=300)
        assert proc.returncode == 0, proc.stderr
        assert proc.stdout.strip() == "True"


def test_an_unchecked_numba_is_left_alone(monkeypatch):
    import numba.core.caching as caching

    import femkit.numba_cache as numba_cache

    before = caching.Cache.load_overload
    monkeypatch.setattr(numba_cache, "CHECKED", ())
    monkeypatch.setattr(numba_cache, "_INSTALLED", False)
    assert numba_cache.lean_cache_loads() is False
    assert caching.Cache.load_overload is before
