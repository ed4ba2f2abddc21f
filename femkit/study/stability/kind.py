"""Registers ``kind: stability`` (its modules by convention: :mod:`femkit.study.declare`)."""

from ..declare import study_kind

KIND = study_kind("stability", __package__)
