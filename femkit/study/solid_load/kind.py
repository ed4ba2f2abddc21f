"""Registers ``kind: solid_load`` (its modules by convention: :mod:`femkit.study.declare`)."""

from ..declare import study_kind

KIND = study_kind("solid_load", __package__)
