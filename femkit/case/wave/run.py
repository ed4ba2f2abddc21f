"""Prepare and run a ``problem: wave`` case (the shared steps: :mod:`femkit.case.transient.setup`,
:mod:`femkit.case.transient.run`)."""

from __future__ import annotations

import os
from typing import Any, Callable

from .result import WaveResult
from .spec import WaveSpec

__all__ = ["prepare_wave", "run_wave"]


def prepare_wave(case) -> None:
    """Check a validated wave file and build its :class:`WaveSpec` (``case.spec``); the checks
    are those of :func:`femkit.case.transient.setup.prepare_transient`."""
    import dataclasses

    from ...dynamics.mol import WAVE_INTEGRATORS
    from ..transient.setup import prepare_transient

    spec = prepare_transient(case, "rho", WAVE_INTEGRATORS, ("initial_velocity",))
    case.spec = WaveSpec(**{f.name: getattr(spec, f.name) for f in dataclasses.fields(spec)})


def run_wave(case, output_dir: str | os.PathLike | None = None, quiet: bool = False,
             write: bool = True, echo: Callable[[str], Any] | None = None) -> WaveResult:
    """Run a prepared wave case (:func:`femkit.case.transient.run.run_transient`)."""
    from ...dynamics.mol import WAVE_INTEGRATORS
    from ..transient.run import run_transient

    return run_transient(case, "rho", WAVE_INTEGRATORS, second_order=True,
                         output_dir=output_dir, quiet=quiet, write=write, echo=echo,
                         result_type=WaveResult)
