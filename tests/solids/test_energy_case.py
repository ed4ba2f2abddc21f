"""A material designed by its energy and the projective integrator through the solid case
files: the energy form of a built-in gives the built-in's equilibrium, a bad energy is one line
and exit 2 when the case loads, and a dynamic case runs with ``integrator: projective``."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

import femkit
from femkit.case.load import read_yaml
from femkit.cli import main
from femkit.solids.materials import StableNeoHookean, lame_from_young

CASES = Path(__file__).parents[2] / "cases"
MU, LAM = lame_from_young(1000.0, 0.3)

BASE = {
    "problem": "solid",
    "name": "cube",
    "mesh": {"geometry": "unit_cube", "h": 0.5},
    "material": {"model": "stable_neo_hookean", "E": 1000.0, "nu": 0.3, "density": 1.0},
    "boundaries": [{"tag": "xmin", "type": "fixed"},
                   {"tag": "xmax", "type": "traction", "traction": [0.0, 0.0, -20.0]}],
    "static": True,
    "output": {"png": False},
}


def _run(data, tmp_path):
    case = femkit.case.load.case_from_dict(copy.deepcopy(data), tmp_path)
    return case.run(write=False, quiet=True)


@pytest.mark.xdist_group("designed_stable_neo_hookean")   # test_energy_designed.py's module too
def test_energy_of_a_builtin_in_a_case_gives_the_builtins_equilibrium(tmp_path):
    designed = dict(BASE, material={"energy": {"W": StableNeoHookean.energy_expression.W},
                                    "constants": {"mu": MU, "lam": LAM}, "density": 1.0})
    a, b = _run(BASE, tmp_path), _run(designed, tmp_path)
    xa, xb = a.fields(-1)["principal_stretches"], b.fields(-1)["principal_stretches"]
    assert np.abs(xa - 1.0).max() > 1e-3
    np.testing.assert_allclose(xb, xa, rtol=0, atol=1e-10)


@pytest.mark.parametrize("material,words", [
    ({"energy": {"f": "mu*(s-1)**2 + mu*s"}, "constants": {"mu": 1.0}}, "not stress-free"),
    ({"energy": {"f": "mu*(s-1)**2", "q": "1"}, "constants": {"mu": 1.0}}, "q"),
    ({"energy": {"f": "__import__('os')"}}, "not allowed"),
], ids=["not_stress_free", "unknown_key", "unsafe"])
def test_bad_energy_in_a_case_is_one_line_exit_2(material, words, tmp_path, capsys):
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(dict(BASE, material=material)))
    out = tmp_path / "out"
    assert main(["solve", str(path), "--output", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_dynamic_case_runs_with_the_projective_integrator(tmp_path):
    data = read_yaml(CASES / "solid_beam_vibration.yaml")
    data.update(integrator={"method": "projective", "options": {"iterations": 10}}, t_end=0.02,
                output={"every": 1, "png": False})
    result = _run(data, tmp_path)
    assert np.all(np.isfinite([e["total"] for e in result.energies]))
    assert len(result.energies) >= 2
