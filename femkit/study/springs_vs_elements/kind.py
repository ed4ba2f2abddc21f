"""Registers ``kind: springs_vs_elements`` (its modules by convention: :mod:`femkit.study.declare`)."""

from ..declare import study_kind

KIND = study_kind("springs_vs_elements", __package__)
