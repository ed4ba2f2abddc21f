"""Registers ``kind: wave_energy`` (its modules by convention: :mod:`femkit.study.declare`)."""

from ..declare import study_kind

KIND = study_kind("wave_energy", __package__, default_solver="direct")
