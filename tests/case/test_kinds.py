"""The one registry of file kinds: every problem and study kind resolves to a schema and callables,
unknown names list the valid ones of their family, a registered kind is dispatched."""

import subprocess
import sys

import pytest

import femkit.study  # noqa: F401  hands KINDS the finder of the study kinds
from femkit.case.load import Case, case_from_dict
from femkit.errors import CaseFileError, UnknownNameError
from femkit.kinds import KINDS, Kind, register_kind

PROBLEMS = KINDS.names("problem")
STUDIES = KINDS.names("kind")


def test_builtin_kinds_are_discovered():
    assert {"poisson", "mass_spring"} <= set(PROBLEMS)
    assert {"poisson_convergence", "dynamics_work_precision", "stability", "adaptive",
            "cloth_work_precision"} <= set(STUDIES)


def test_the_case_layer_loads_no_study_module():
    """Every problem kind, and a case file loaded, without one femkit.study module imported: the
    registry is a leaf (femkit.kinds) and each family's package finds its own kinds."""
    code = ("import sys, femkit.case; from femkit.kinds import KINDS; "
            "assert KINDS.names('problem') == ['heat', 'mass_spring', 'poisson', 'solid', 'wave'], KINDS.names('problem'); "
            "femkit.case.case_from_dict({'problem': 'poisson', 'mesh': {'geometry': 'unit_square', "
            "'h': 0.5}, 'source': '1', 'boundary': {'dirichlet': [{'tags': ['boundary'], 'value': 0}]}}); "
            "bad = sorted(m for m in sys.modules if m.startswith('femkit.study')); assert not bad, bad")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]


def test_the_former_module_name_is_the_same_registry():
    from femkit.case import kinds as former

    assert former.KINDS is KINDS and former.register_kind is register_kind and former.Kind is Kind


@pytest.mark.parametrize("name", PROBLEMS, ids=PROBLEMS)
def test_problem_entries_resolve(name):
    k = KINDS.get(name, "problem")
    schema = k.get_schema()
    assert schema["type"] == "object" and schema["additionalProperties"] is False
    assert "problem" in schema["properties"]
    assert callable(k.prepare) and callable(k.run) and callable(k.plan)


@pytest.mark.parametrize("name", STUDIES, ids=STUDIES)
def test_study_entries_resolve(name):
    from femkit.study.schema import schema_for

    k = KINDS.get(name, "kind")
    assert callable(k.prepare) and callable(k.run) and callable(k.report) and callable(k.summary)
    full = schema_for(name)
    assert full["additionalProperties"] is False and "quick" in full["properties"]


def test_unknown_problem_lists_the_valid_ones_of_its_family():
    with pytest.raises(UnknownNameError, match="valid problems: heat, mass_spring, poisson, solid, wave$"):
        KINDS.get("heatbar", "problem")
    with pytest.raises(UnknownNameError, match="unknown study kind 'poisson'"):
        KINDS.get("poisson", "kind")  # a problem is not a study kind
    with pytest.raises(CaseFileError, match="missing required key 'problem'"):
        case_from_dict({"mesh": {}})
    with pytest.raises(CaseFileError, match="problem: unknown problem 'stability'"):
        case_from_dict({"problem": "stability"})


def test_kind_key_is_checked():
    with pytest.raises(ValueError, match="Kind.key must be one of problem, kind"):
        Kind("x", "case", {}, print, print)


def test_a_registered_problem_kind_is_dispatched_and_its_data_is_read_only(tmp_path):
    seen = {}
    schema = {"type": "object", "additionalProperties": False,
              "properties": {"problem": {"const": "toy"}, "n": {"type": "integer", "default": 3}}}

    def prepare(case: Case):
        seen["prepared"] = case.data["n"]
        case.spec = ("toy", case.data["n"])

    def run(case, output_dir=None, quiet=False, write=True, echo=None):
        return ("ran", case.spec, write)

    register_kind(Kind("toy", "problem", schema, prepare, run))
    try:
        case = case_from_dict({"problem": "toy"}, tmp_path)
        assert seen == {"prepared": 3}
        assert case.run(write=False) == ("ran", ("toy", 3), False)
        with pytest.raises(TypeError, match="read-only"):
            case.data["n"] = 4
        with pytest.raises(CaseFileError, match="m: unknown key"):
            case_from_dict({"problem": "toy", "m": 1}, tmp_path)
        with pytest.raises(ValueError, match="twice"):
            register_kind(Kind("toy", "problem", schema, prepare, run))
        from femkit.case.budget import plan_case

        plan = plan_case(case)  # no cost model: a plan that says so, nothing refused
        assert plan.stages == [] and "no cost model for problem 'toy'" in plan.assumptions[0]
    finally:
        KINDS.remove("toy")
    assert "toy" not in KINDS


def test_each_kind_declares_its_default_solver_and_a_file_without_one_gets_it():
    """The default method of a kind's solves lives on the kind (no table keyed by kind names
    elsewhere): a registered solver, and what a file without ``method`` runs with."""
    from femkit.solvers import SOLVERS
    from femkit.solvers.core import defaults

    assert not hasattr(defaults, "DEFAULT_METHOD")
    declared = {n: KINDS.get(n).default_solver for n in KINDS.names() if KINDS.get(n).default_solver}
    assert {"poisson", "mass_spring", "cloth_work_precision"} <= set(declared)
    assert all(m in SOLVERS.names() for m in declared.values()), declared
    case = case_from_dict({"problem": "poisson", "mesh": {"geometry": "unit_square", "h": 0.5},
                           "source": "1", "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]}})
    assert case.solver.method == declared["poisson"] == "pcg"


def test_a_loaded_case_is_immutable_and_holds_its_solver_spec_once(tmp_path):
    """After prepare nothing of a Case is rebound (overrides and run options make a new case),
    and its solver spec is the run spec's (no second copy to drift)."""
    import dataclasses

    from femkit.case.load import RunOptions

    case = case_from_dict({"problem": "poisson", "mesh": {"geometry": "unit_square", "h": 0.5},
                           "source": "1", "boundary": {"dirichlet": [{"tags": ["boundary"]}]},
                           "solver": {"method": "cg", "rtol": 1e-9}}, tmp_path)
    assert case.solver is case.spec.solver and case.solver.method == "cg"
    for name, value in (("spec", None), ("name", "other"), ("options", RunOptions(force=True))):
        with pytest.raises(dataclasses.FrozenInstanceError, match="immutable"):
            setattr(case, name, value)
    with pytest.raises(TypeError, match="read-only"):
        case.functions["source"] = case.functions["source"]
    with pytest.raises(AttributeError):
        case.solver = None
    with pytest.raises(dataclasses.FrozenInstanceError):
        case.options.force = True  # the options are frozen too
    forced = case.with_options(force=True)
    assert forced is not case and forced.options.force and not case.options.force
    assert forced.spec is case.spec and forced.solver is case.solver
    direct = case.replace(spec=dataclasses.replace(case.spec, solver=dataclasses.replace(
        case.spec.solver, method="direct")))
    assert (direct.solver.method, case.solver.method) == ("direct", "cg")
    with pytest.raises(dataclasses.FrozenInstanceError):
        direct.spec = case.spec

