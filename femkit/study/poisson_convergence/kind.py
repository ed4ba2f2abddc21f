"""Registers ``kind: poisson_convergence`` (its modules by convention: :mod:`femkit.study.declare`)."""

from ..declare import study_kind

KIND = study_kind("poisson_convergence", __package__)
