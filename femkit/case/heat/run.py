"""Prepare and run a ``problem: heat`` case (the shared steps: :mod:`femkit.case.transient.setup`,
:mod:`femkit.case.transient.run`)."""

from __future__ import annotations

import os
from typing import Any, Callable

from ...errors import CaseFileError
from .result import HeatResult
from .spec import HeatSpec

__all__ = ["prepare_heat", "run_heat"]


def prepare_heat(case) -> None:
    """Check a validated heat file and build its :class:`HeatSpec` (``case.spec``).

    Raises
    ------
    CaseFileError
        ``rtol_t`` with an integrator that has no embedded error estimate (the valid ones
        named), besides the common checks of :func:`femkit.case.transient.setup.prepare_transient`.
    """
    import dataclasses

    from ...dynamics.mol import HEAT_INTEGRATORS
    from ..transient.setup import prepare_transient

    spec = prepare_transient(case, "rho_c", HEAT_INTEGRATORS)
    if spec.rtol_t is not None:
        from ...dynamics.mol import get_scheme

        embedded = [n for n in HEAT_INTEGRATORS.names() if get_scheme(HEAT_INTEGRATORS, n).embedded]
        if not get_scheme(HEAT_INTEGRATORS, spec.integrator[0], **dict(spec.integrator[1])).embedded:
            raise CaseFileError(f"rtol_t: adaptive steps need an integrator with an embedded error "
                                f"estimate; valid: {', '.join(embedded)}")
    case.spec = HeatSpec(**{f.name: getattr(spec, f.name) for f in dataclasses.fields(spec)})


def run_heat(case, output_dir: str | os.PathLike | None = None, quiet: bool = False,
             write: bool = True, echo: Callable[[str], Any] | None = None) -> HeatResult:
    """Run a prepared heat case (:func:`femkit.case.transient.run.run_transient`)."""
    from ...dynamics.mol import HEAT_INTEGRATORS
    from ..transient.run import run_transient

    return run_transient(case, "rho_c", HEAT_INTEGRATORS, second_order=False,
                         output_dir=output_dir, quiet=quiet, write=write, echo=echo,
                         result_type=HeatResult)
