"""`femkit solve`, `femkit check` and the studies all go through one Poisson pipeline:
:class:`femkit.fem.PoissonProblem` (counted by wrapping its ``assemble_matrices``)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from femkit.cli import main
from femkit.fem.poisson import PoissonProblem

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def count(monkeypatch):
    calls = []
    original = PoissonProblem.assemble_matrices

    def counted(self, **options):
        calls.append(self.mesh.n_triangles)
        return original(self, **options)

    monkeypatch.setattr(PoissonProblem, "assemble_matrices", counted)
    return calls


@pytest.fixture
def small_case(tmp_path):
    data = yaml.safe_load((ROOT / "cases" / "poisson_unit_square.yaml").read_text())
    data["mesh"]["h"] = 0.25
    data.pop("output", None)
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_solve_goes_through_poisson_problem(count, small_case, tmp_path):
    assert main(["solve", str(small_case), "--quiet", "--output", str(tmp_path / "out")]) == 0
    assert len(count) == 1


def test_check_goes_through_poisson_problem(count, small_case):
    assert main(["check", str(small_case), "--quiet"]) == 0
    assert len(count) == 1  # one assembly: the case's load rule, handed to scikit-fem too


def test_convergence_study_goes_through_poisson_problem(count, tmp_path):
    from femkit.study import run_study, study_from_dict

    data = yaml.safe_load((ROOT / "studies" / "poisson_convergence.yaml").read_text())
    data.pop("stop_at_discretisation_error")
    data.update(reference="none", quadrature=["barycentric"], warmup=0)
    study = study_from_dict(data, ROOT / "studies", quick=True)
    result = run_study(study, write=False)
    levels = sorted({r["level"] for r in result.records})
    assert len(count) == len(levels) >= 3


def test_stress_study_goes_through_poisson_problem(count):
    from femkit.study import run_study, study_from_dict

    study = study_from_dict({"kind": "stability", "warmup": 0,
                             "cases": [{"type": "poisson_contrast", "name": "c", "values": [1.0, 1e3], "n": 8},
                                       {"type": "poisson_neumann", "name": "n", "n": 8}],
                             "solvers": [{"method": "cg"}]})
    run_study(study, write=False)
    assert len(count) == 3
