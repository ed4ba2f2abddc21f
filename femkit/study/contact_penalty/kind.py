"""Registers ``kind: contact_penalty`` (its modules by convention: :mod:`femkit.study.declare`)."""

from ..declare import study_kind

KIND = study_kind("contact_penalty", __package__)
