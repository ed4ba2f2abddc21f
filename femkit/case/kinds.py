"""The registry of file kinds under its former name: :mod:`femkit.kinds` (a leaf below case/ and study/).

Kept so that plugins written as ``from femkit.case.kinds import Kind, register_kind`` keep working;
femkit's own modules import :mod:`femkit.kinds`.
"""

from ..kinds import FAMILIES, KINDS, Kind, KindRegistry, register_kind

__all__ = ["Kind", "KINDS", "KindRegistry", "register_kind", "FAMILIES"]
