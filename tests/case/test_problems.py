"""Problem-type dispatch: every registered problem resolves to a schema and two callables."""

import pytest

from femkit.case.load import case_from_dict
from femkit.case.problems import PROBLEMS, get_problem, register_problem
from femkit.errors import CaseFileError, UnknownNameError


@pytest.mark.parametrize("name", sorted(PROBLEMS), ids=sorted(PROBLEMS))
def test_problem_entries_resolve(name):
    p = get_problem(name)
    schema = p.get_schema()
    assert schema["type"] == "object" and schema["additionalProperties"] is False
    assert "problem" in schema["properties"]
    assert callable(p.get_prepare()) and callable(p.get_run())


def test_unknown_problem_lists_the_valid_ones():
    with pytest.raises(UnknownNameError, match="valid problems: .*poisson"):
        get_problem("heat")
    with pytest.raises(CaseFileError, match="missing required key 'problem'"):
        case_from_dict({"mesh": {}})


def test_a_registered_problem_type_is_dispatched(tmp_path):
    seen = {}
    schema = {"type": "object", "additionalProperties": False,
              "properties": {"problem": {"const": "toy"}, "n": {"type": "integer", "default": 3}}}

    def prepare(case):
        seen["prepared"] = case.data["n"]

    def run(case, output_dir=None, quiet=False, write=True, echo=None):
        return ("ran", case.data["n"], write)

    register_problem("toy", schema, prepare, run)
    try:
        case = case_from_dict({"problem": "toy"}, tmp_path)
        assert seen == {"prepared": 3}
        assert case.run(write=False) == ("ran", 3, False)
        with pytest.raises(CaseFileError, match="m: unknown key"):
            case_from_dict({"problem": "toy", "m": 1}, tmp_path)
        with pytest.raises(ValueError, match="twice"):
            register_problem("toy", schema, prepare, run)
    finally:
        PROBLEMS.remove("toy")
