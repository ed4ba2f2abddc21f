"""Importing petsc4py and mpi4py, lazily, with one clear error when they are missing."""

from __future__ import annotations

import sys

from ...errors import BackendUnavailableError

#: What to do when petsc4py is missing (the path is relative to the femkit checkout).
INSTALL_HINT = ("pip install 'femkit[petsc]' (builds PETSc from source), or run scripts/install-petsc.sh (Debian's PETSc 3.18 + Open MPI in .venv-petsc) and "
                "use .venv-petsc/bin/python or .venv-petsc/bin/femkit")


def require_petsc():
    """Return the ``petsc4py.PETSc`` module (initialised with no command-line options).

    Raises
    ------
    BackendUnavailableError
        petsc4py or mpi4py cannot be imported (or petsc4py was built against another numpy).
    """
    mod = sys.modules.get("petsc4py.PETSc")
    if mod is not None:
        return mod
    try:
        import mpi4py  # noqa: F401  (MPI before PETSc: PETSc then uses mpi4py's MPI_Init)
        from mpi4py import MPI  # noqa: F401
        import petsc4py

        petsc4py.init([])  # no sys.argv: femkit's own flags are not PETSc options
        from petsc4py import PETSc
    except (ImportError, RuntimeError, ValueError) as exc:  # numpy ABI mismatch is ImportError/RuntimeError
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise BackendUnavailableError(
            f"the petsc backend needs petsc4py and mpi4py, which cannot be imported here "
            f"({reason}): {INSTALL_HINT}") from None
    return PETSc


def petsc_available() -> bool:
    """True when :func:`require_petsc` would succeed (imports petsc4py if so)."""
    try:
        require_petsc()
    except BackendUnavailableError:
        return False
    return True


def world():
    """PETSc's world communicator (``PETSc.COMM_WORLD``)."""
    return require_petsc().COMM_WORLD


def mpi_comm(comm):
    """The mpi4py communicator of a PETSc communicator (for Python-object collectives)."""
    return comm.tompi4py()
