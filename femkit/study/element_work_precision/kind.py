"""Registers ``kind: element_work_precision`` (its modules by convention: :mod:`femkit.study.declare`)."""

from ..declare import study_kind

KIND = study_kind("element_work_precision", __package__)
