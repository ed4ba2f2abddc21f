"""``kind: solid_load`` (studies/solid_load.yaml, quick mode): the materials at a large tip load
behave as theory says, and the elastica the report draws is Bisshopp & Drucker's."""

from pathlib import Path

import pytest

from femkit.study.load import load_study
from femkit.study.solid_load.run import elastica_deflection

STUDY = Path(__file__).parents[2] / "studies" / "solid_load.yaml"


@pytest.mark.parametrize("alpha, published", [(1.0, 0.302), (2.0, 0.494), (3.0, 0.603),
                                              (5.0, 0.714), (10.0, 0.811)])
def test_elastica_matches_bisshopp_and_drucker(alpha, published):
    assert elastica_deflection(alpha) == pytest.approx(published, abs=1e-3)


@pytest.mark.slow
def test_materials_at_a_large_load_differ_as_theory_says(tmp_path):
    """Quick mode: tip load up to alpha = P L^2 / EI = 12.3 in 4 steps. The linear material has
    no geometric nonlinearity (deflection proportional to the load); the rotation-invariant ones
    deflect less than it, more than the inextensible elastica (this beam is stubby); StVK, which
    softens in compression, has no equilibrium at the larger loads where co-rotational and
    stable neo-Hookean carry the whole load."""
    result = load_study(STUDY, quick=True).run(tmp_path / "report", progress=False)
    rec = result.records
    by = {m: [r for r in rec if r["material"] == m] for m in ("linear", "corotational", "stvk",
                                                              "stable_neo_hookean")}
    lin = by["linear"]
    assert len(lin) == 4
    per_load = [r["tip_deflection"] / r["load"] for r in lin]
    assert max(per_load) == pytest.approx(min(per_load), rel=1e-8)
    for m in ("corotational", "stable_neo_hookean"):
        assert len(by[m]) == 4
        for r in by[m]:
            assert r["elastica_ratio"] < r["ratio_to_linear"] < 1.0
    assert len(by["stvk"]) < 4 and any("stvk: no equilibrium" in n for n in result.notes)
    assert (tmp_path / "report" / "figures" / "solid_load.png").is_file()


def test_a_designed_base_material_runs_each_material_with_its_moduli_at_rest(tmp_path):
    """A base case whose material is designed by its energy (once refused with
    'material.constants: unknown key'): each material of the study runs with the designed
    energy's moduli at rest, so the linear material deflects exactly as it does when the base
    case gives the same moduli as E and nu."""
    import yaml

    E, nu = 1.0e6, 0.3
    mu, lam = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    base = yaml.safe_load((STUDY.parent.parent / "cases" / "solid_cantilever.yaml").read_text())
    designed = dict(base, material={"energy": {"f": "mu*(s-1)**2", "h": "lam/2*(J-1)**2"},
                                    "constants": {"mu": mu, "lam": lam}, "density": 1000.0})
    deflections = {}
    for name, case in (("plain", base), ("designed", designed)):
        (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(case))
        (tmp_path / f"{name}_study.yaml").write_text(yaml.safe_dump({
            "kind": "solid_load", "base_case": f"{name}.yaml", "materials": ["linear"],
            "scale": 10.0, "load_steps": 1, "case_overrides": {"mesh": {"h": 1.0}}}))
        result = load_study(tmp_path / f"{name}_study.yaml").run(tmp_path / name, progress=False)
        (rec,) = result.records
        deflections[name] = rec["tip_deflection"]
        assert rec["alpha"] == pytest.approx(10 * 800 * 16 / (E / 12), rel=1e-9)
    assert deflections["designed"] == pytest.approx(deflections["plain"], rel=1e-9)
    assert abs(deflections["plain"]) > 1e-3  # the beam bent
