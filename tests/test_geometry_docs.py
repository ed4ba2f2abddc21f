"""docs/case-files.md's geometry section is the registry's: generated from ``femkit.mesh.GEOMETRIES``
(``scripts/geometry_docs.py``) and checked here, so it cannot drift.

- the section in the docs is exactly what the script renders from the live registry;
- every geometry's description (its builder's docstring, which the section quotes) names each of
  its registered tags and parameters;
- where a description places a tag on a plane, ``tag (x = value)``, the generated mesh's faces
  (edges) of that tag lie on it (with the default parameters).
"""

import importlib.util
import inspect
import re
from pathlib import Path

import numpy as np
import pytest

from femkit.mesh import GEOMETRIES, generate

ROOT = Path(__file__).resolve().parents[1]
NAMES = GEOMETRIES.names()


def _script():
    spec = importlib.util.spec_from_file_location("geometry_docs", ROOT / "scripts" / "geometry_docs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_docs_section_is_generated_from_the_registry():
    script = _script()
    rendered = script.render()
    assert script.current((ROOT / "docs" / "case-files.md").read_text()) == rendered, (
        "docs/case-files.md's geometry section is out of date: python scripts/geometry_docs.py --write")
    for name in NAMES:  # one table row and one description per registered geometry
        assert rendered.count(f"| `{name}` |") == 1 and rendered.count(f"\n- `{name}`: ") == 1
    assert "#### 2D geometries" in rendered and "#### 3D geometries" in rendered


@pytest.mark.parametrize("name", NAMES)
def test_the_description_names_every_tag_and_parameter(name):
    g = GEOMETRIES.get(name)
    doc = g.build.__doc__ or ""
    missing = [t for t in g.boundary_tags + g.cell_tags if f"``{t}``" not in doc]
    assert not missing, f"{name}: the docstring does not describe the tags {missing}"
    params = [p for p in inspect.signature(g.build).parameters if p != "h"]
    assert all(re.search(rf"\b{p}\b", doc) for p in params), (name, params)


#: ``tag`` (x = 0) / (y = width) / (z = height) in a docstring: a number or one parameter name
PLANE = re.compile(r"``(\w+)`` \(([xyz]) = ([\w.]+)[,)]")


def _planes(name):
    g = GEOMETRIES.get(name)
    defaults = {n: p.default for n, p in inspect.signature(g.build).parameters.items() if n != "h"}
    out = []
    for tag, axis, value in PLANE.findall(g.build.__doc__ or ""):
        if re.fullmatch(r"-?\d+(\.\d+)?", value):
            out.append((tag, "xyz".index(axis), float(value)))
        elif isinstance(defaults.get(value), (int, float)):
            out.append((tag, "xyz".index(axis), float(defaults[value])))
    return out


PLACED = [(name, plane) for name in NAMES for plane in _planes(name)]


def test_the_plane_statements_are_found():
    placed = {name for name, _ in PLACED}
    assert {"beam", "unit_cube", "kuhn_cube", "unit_square", "rectangle", "cylinder"} <= placed


@pytest.fixture(scope="module")
def meshes():
    cache = {}

    def mesh(name):
        if name not in cache:
            g = GEOMETRIES.get(name)
            cache[name] = generate(name, 0.5 if g.dim == 3 else 0.25)
        return cache[name]

    return mesh


@pytest.mark.parametrize("name, plane", PLACED, ids=[f"{n}-{p[0]}" for n, p in PLACED])
def test_a_tag_lies_where_its_description_says(meshes, name, plane):
    tag, axis, value = plane
    mesh = meshes(name)
    facets = mesh.boundary_facets if mesh.dim == 3 else mesh.boundary_edges
    nodes = np.unique(facets[mesh.boundary_tags == mesh.tag(tag)])
    assert nodes.size, (name, tag)
    assert np.abs(mesh.points[nodes, axis] - value).max() <= 1e-9 * max(1.0, abs(value)), (name, tag)
