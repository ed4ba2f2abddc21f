"""femkit: P1 finite elements for Poisson problems and mass-spring dynamics.

Importing femkit is cheap: heavy modules (gmsh, pyamg, matplotlib, numba, scikit-fem)
are imported only by the code path that needs them.
"""

from ._version import __version__  # noqa: F401

from .errors import FemkitError  # noqa: F401  (cheap)


def load_case(path, **overrides):
    """Load and validate a case/scene file; see :func:`femkit.case.load_case`."""
    from .case import load_case as _load

    return _load(path, **overrides)
