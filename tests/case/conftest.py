"""Helpers for case-file tests: write a case YAML into tmp_path."""

import copy

import pytest
import yaml

BASE = {
    "problem": "poisson",
    "mesh": {"geometry": "unit_square", "h": 0.25},
    "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
    "solver": {"method": "direct"},
}


@pytest.fixture
def base_case():
    """A small valid Poisson case (unit square, h = 0.25, direct solver) as a fresh dict."""
    return copy.deepcopy(BASE)


@pytest.fixture
def write_case(tmp_path):
    """write_case(data=None, name='case.yaml', text=None) -> path of the written case file."""

    def _write(data=None, name="case.yaml", text=None):
        path = tmp_path / name
        path.write_text(text if text is not None else yaml.safe_dump(data if data is not None else BASE))
        return path

    return _write
