"""Case-file schema: one-line errors with key paths, valid alternatives, defaults, paths."""

import copy
from pathlib import Path

import pytest

from femkit.case import load_case
from femkit.case.load import case_from_dict
from femkit.case.poisson.schema import POISSON_SCHEMA
from femkit.errors import CaseFileError, ExpressionError, InputError, UnknownNameError


def with_(change, base):
    data = copy.deepcopy(base)
    change(data)
    return data


def error_of(data, tmp_path, exc=InputError):
    with pytest.raises(exc) as info:
        case_from_dict(data, tmp_path)
    msg = str(info.value)
    assert "\n" not in msg
    return msg


BAD = [
    ("misspelled-top-key", lambda d: d.update(soruce="1"), CaseFileError,
     ["soruce: unknown key", "did you mean 'source'", "boundary", "coefficient", "mesh"]),
    ("misspelled-solver-key", lambda d: d["solver"].update(preconditoner="amg"), CaseFileError,
     ["solver.preconditoner: unknown key", "did you mean 'preconditioner'", "rtol", "maxiter"]),
    ("misspelled-in-list", lambda d: d["boundary"]["dirichlet"][0].update(valeu=1), CaseFileError,
     ["boundary.dirichlet[0].valeu", "did you mean 'value'", "tags"]),
    ("wrong-type-h", lambda d: d["mesh"].update(h="small"), CaseFileError,
     ["mesh.h", "expected a number", "string 'small'"]),
    ("h-not-positive", lambda d: d["mesh"].update(h=0), CaseFileError, ["mesh.h", "must be > 0"]),
    ("rtol-negative", lambda d: d["solver"].update(rtol=-1e-8), CaseFileError,
     ["solver.rtol", "must be > 0"]),
    ("maxiter-float", lambda d: d["solver"].update(maxiter=2.5), CaseFileError,
     ["solver.maxiter", "expected an integer"]),
    ("negative-kappa", lambda d: d.update(coefficient=-1.0), CaseFileError,
     ["coefficient", "must be > 0"]),
    ("kappa-list", lambda d: d.update(coefficient=[1, 2]), CaseFileError,
     ["coefficient", "expected a positive number, an expression string"]),
    ("regions-typo", lambda d: d.update(coefficient={"regons": {"a": 1}}), CaseFileError,
     ["coefficient.regons: unknown key", "did you mean 'regions'"]),
    ("mesh-both", lambda d: d["mesh"].update(file="x.msh"), CaseFileError,
     ["mesh", "either 'geometry'"]),
    ("mesh-missing-h", lambda d: d["mesh"].pop("h"), CaseFileError, ["mesh", "either 'geometry'"]),
    ("no-boundary", lambda d: d.pop("boundary"), CaseFileError, ["missing required key 'boundary'"]),
    ("empty-tags", lambda d: d["boundary"]["dirichlet"][0].update(tags=[]), CaseFileError,
     ["boundary.dirichlet[0].tags", "at least 1"]),
    ("unknown-problem", lambda d: d.update(problem="navier_stokes"), CaseFileError,
     ["problem", "navier_stokes", "poisson"]),
    ("unknown-solver", lambda d: d["solver"].update(method="gmres"), UnknownNameError,
     ["solver.method", "'gmres'", "cg", "direct", "pcg"]),
    ("unknown-preconditioner", lambda d: d["solver"].update(method="pcg", preconditioner="ilu"),
     UnknownNameError, ["solver.preconditioner", "'ilu'", "amg", "ic0", "jacobi"]),
    ("preconditioner-without-pcg", lambda d: d["solver"].update(preconditioner="amg"),
     CaseFileError, ["solver.preconditioner", "only valid with method 'pcg'"]),
    ("unknown-geometry", lambda d: d["mesh"].update(geometry="circle"), UnknownNameError,
     ["mesh.geometry", "'circle'", "disk", "l_shape"]),
    ("bad-geometry-param", lambda d: d["mesh"].update(params={"radius": 2}), CaseFileError,
     ["mesh.params", "unit_square"]),
    ("unknown-quadrature", lambda d: d.update(quadrature={"load": "gauss99"}), UnknownNameError,
     ["quadrature.load", "gauss99", "barycentric", "gauss6"]),
    ("unsafe-source", lambda d: d.update(source="__import__('os').system('ls')"), ExpressionError,
     ["source:", "not allowed"]),
    ("unsafe-exact", lambda d: d.update(exact={"u": "x.__class__"}), ExpressionError,
     ["exact.u:", "attribute access"]),
    ("grad-one-component", lambda d: d.update(exact={"u": "x", "grad": ["1"]}), CaseFileError,
     ["exact.grad", "at least 2"]),
    ("bad-constant-name", lambda d: d.update(constants={"1k": 2.0}), CaseFileError,
     ["constants"]),
]


@pytest.mark.parametrize("change, exc, pieces", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_case_gives_one_line_message_naming_the_problem(change, exc, pieces, tmp_path,
                                                             base_case):
    msg = error_of(with_(change, base_case), tmp_path, exc)
    for piece in pieces:
        assert piece in msg, (piece, msg)


def test_defaults_filled_and_paths_resolved(write_case, tmp_path, base_case):
    case = load_case(write_case())
    d = case.data
    assert d["coefficient"] == 1.0 and d["mesh"]["refine"] == 0
    assert d["quadrature"]["load"] == "barycentric"
    assert d["solver"]["rtol"] == 1e-10 and d["solver"]["preconditioner"] == "none"
    assert d["output"] == {"dir": str(tmp_path / "runs" / "case"), "vtu": True, "xdmf": False,
                           "plot": False}
    assert case.name == "case"
    pcg = load_case(write_case(with_(lambda d: d["solver"].update(method="pcg"), base_case)))
    assert pcg.data["solver"]["preconditioner"] == "amg"


def test_relative_mesh_file_is_resolved_against_the_case_file(tmp_path, write_case, base_case):
    sub = tmp_path / "cases"
    sub.mkdir()
    (tmp_path / "m.msh").write_text("not read at load time")
    data = with_(lambda d: d.update(mesh={"file": "../m.msh"}, output={"dir": "out"}), base_case)
    case = load_case(write_case(data, name="cases/c.yaml"))
    assert Path(case.data["mesh"]["file"]) == (tmp_path / "m.msh").resolve()
    assert Path(case.data["output"]["dir"]) == (sub / "out").resolve()


def test_missing_mesh_file_names_the_resolved_path(write_case, tmp_path, base_case):
    data = with_(lambda d: d.update(mesh={"file": "../meshes/none.msh"}), base_case)
    with pytest.raises(CaseFileError) as info:
        load_case(write_case(data))
    assert str((tmp_path.parent / "meshes" / "none.msh").resolve()) in str(info.value)


def test_yaml_syntax_error_reports_the_line(write_case):
    path = write_case(text="problem: poisson\nmesh: {geometry: unit_square, h: 0.1\nsource: 1\n")
    with pytest.raises(CaseFileError, match=r"line \d+"):
        load_case(path)


def test_yaml_12_floats_are_numbers(write_case):
    path = write_case(text=(
        "problem: poisson\nmesh: {geometry: unit_square, h: 5e-1}\n"
        "boundary: {dirichlet: [{tags: [boundary]}]}\nsolver: {method: cg, rtol: 1e-8}\n"))
    case = load_case(path)
    assert case.data["mesh"]["h"] == 0.5 and case.data["solver"]["rtol"] == 1e-8


def test_overrides_merge_into_nested_keys(write_case):
    case = load_case(write_case(), mesh={"h": 0.125}, solver__rtol=1e-6)
    assert case.data["mesh"] == {"geometry": "unit_square", "h": 0.125, "refine": 0}
    assert case.data["solver"]["rtol"] == 1e-6 and case.data["solver"]["method"] == "direct"
    with pytest.raises(CaseFileError, match="mesh.hh: unknown key"):
        load_case(write_case(), mesh={"hh": 0.1})


def test_compiled_functions_keep_their_source(write_case, base_case):
    case = load_case(write_case())
    assert case.functions["source"].source == base_case["source"]
    assert "boundary.dirichlet[0].value" in case.functions


def _properties(schema, path=""):
    """Every property name of the schema, recursively (through anyOf/items/additionalProperties)."""
    out = set()
    if isinstance(schema, dict):
        for name, sub in schema.get("properties", {}).items():
            out.add(name)
            out |= _properties(sub)
        for key in ("items", "additionalProperties"):
            if isinstance(schema.get(key), dict):
                out |= _properties(schema[key])
        for key in ("anyOf", "oneOf"):
            for sub in schema.get(key, []):
                out |= _properties(sub)
    return out


def test_every_schema_key_is_documented():
    doc = (Path(__file__).parents[2] / "docs" / "case-files.md").read_text()
    missing = sorted(k for k in _properties(POISSON_SCHEMA) if f"`{k}`" not in doc)
    assert not missing, f"keys missing from docs/case-files.md: {missing}"


def test_schema_forbids_unknown_keys_on_every_object():
    def walk(node, path):
        if isinstance(node, dict):
            if node.get("type") == "object" and "properties" in node:
                assert node.get("additionalProperties") is False, path
            for k, v in node.items():
                walk(v, f"{path}/{k}")
        elif isinstance(node, list):
            for i, v in enumerate(node):
                walk(v, f"{path}/{i}")

    walk(POISSON_SCHEMA, "")
