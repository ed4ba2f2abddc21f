"""Registers ``kind: adaptive`` (its modules by convention: :mod:`femkit.study.declare`)."""

from ..declare import study_kind

KIND = study_kind("adaptive", __package__)
