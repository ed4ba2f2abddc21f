"""Without petsc4py the PETSc backend is one clear error naming the install script."""

from __future__ import annotations

import importlib.util

import pytest

from femkit.errors import BackendUnavailableError, InputError


@pytest.mark.skipif(importlib.util.find_spec("petsc4py") is not None,
                    reason="petsc4py is importable in this interpreter (the error cannot occur)")
def test_missing_petsc4py_names_the_install_script():
    from femkit.solvers.petsc import petsc_available, require_petsc

    with pytest.raises(BackendUnavailableError) as info:
        require_petsc()
    msg = str(info.value)
    assert "scripts/install-petsc.sh" in msg and "\n" not in msg
    assert isinstance(info.value, InputError)  # the command line exits with 2
    assert petsc_available() is False


def test_importing_the_backend_package_imports_no_petsc():
    import subprocess
    import sys

    code = ("import sys, femkit.solvers.petsc, femkit.solvers.petsc.names; "
            "print(sorted(m for m in ('petsc4py', 'mpi4py') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_solve_names_the_backend():
    import numpy as np
    import scipy.sparse as sp

    from femkit.errors import UnknownNameError
    from femkit.solvers import solve

    A = sp.identity(3, format="csr")
    with pytest.raises(UnknownNameError, match="valid solver backends: femkit, petsc"):
        solve(A, np.ones(3), backend="trilinos")
    with pytest.raises(InputError, match="preconditioner_options are not used by the petsc"):
        solve(A, np.ones(3), backend="petsc", preconditioner_options={"shift": 0.1})


@pytest.mark.skipif(importlib.util.find_spec("petsc4py") is not None,
                    reason="petsc4py is importable in this interpreter (the error cannot occur)")
def test_solve_with_petsc_backend_without_petsc4py():
    import numpy as np
    import scipy.sparse as sp

    from femkit.solvers import solve

    with pytest.raises(BackendUnavailableError, match="scripts/install-petsc.sh"):
        solve(sp.identity(3, format="csr"), np.ones(3), backend="petsc")
