"""``kind: solid_load`` (studies/solid_load.yaml, quick mode): the materials at a large tip load
behave as theory says, and the elastica the report draws is Bisshopp & Drucker's."""

from pathlib import Path

import pytest

from femkit.study.load import load_study
from femkit.study.solid_load import elastica_deflection

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
