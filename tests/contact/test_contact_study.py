"""``kind: contact_penalty``: penalty contact penetrates less as its stiffness grows (it never
stops penetrating); barrier contact on the same drop never does."""

import json

import pytest

pytest.importorskip("ipctk")


def test_penalty_penetration_falls_with_stiffness_and_the_barrier_never_penetrates(tmp_path):
    from femkit.cli import main

    f = tmp_path / "study.yaml"
    f.write_text("kind: contact_penalty\ntitle: t\nstiffnesses: [100.0, 1000.0, 10000.0]\n"
                 "n: 5\nt_end: 0.15\n")
    assert main(["study", str(f), "-o", str(tmp_path / "out"), "-q"]) == 0
    records = json.loads((tmp_path / "out" / "results.json").read_text())["records"]
    pen = [r["max_penetration"] for r in records if r["method"] == "penalty"]
    assert all(p > 0 for p in pen) and pen[0] > 5 * pen[1] > 25 * pen[2]
    barrier = [r for r in records if r["method"] == "barrier"][0]
    assert barrier["max_penetration"] == 0.0 and barrier["min_height"] > 0.0
    assert barrier["intersections"] == 0
    assert (tmp_path / "out" / "figures" / "contact_penalty.png").stat().st_size > 1000
