"""The "preconditioner only with pcg" rule has one home and reads the same on every route:
the Python API, a solver spec of a file, and the PETSc backend's name table."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.errors import InputError
from femkit.solvers import SolverSpec, solve
from femkit.solvers.petsc import names
from femkit.solvers.registry import petsc_names

from .conftest import poisson_2d

RULE = ("preconditioner 'ic0' is only valid with method 'pcg', not 'cg' "
        "(use method 'pcg', or no preconditioner)")


def _api():
    solve(poisson_2d(4), np.ones(16), method="cg", preconditioner="ic0")


def _spec():
    SolverSpec.from_mapping({"method": "cg", "preconditioner": "ic0"}, "linear_solver")


def _petsc_spec():
    SolverSpec.from_mapping({"method": "cg", "preconditioner": "ic0", "backend": "petsc"}, "solver")


def _petsc_names():
    names.resolve("cg", "ic0", petsc_names())


@pytest.mark.parametrize("route, prefix", [(_api, ""), (_spec, "linear_solver.preconditioner: "),
                                           (_petsc_spec, "solver.preconditioner: "),
                                           (_petsc_names, "")],
                         ids=["api", "spec", "petsc-spec", "petsc-names"])
def test_one_message_on_every_route(route, prefix):
    with pytest.raises(InputError) as exc:
        route()
    assert str(exc.value) == prefix + RULE
