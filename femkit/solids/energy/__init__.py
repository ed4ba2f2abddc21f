"""Materials designed by their energy of the principal stretches (Xu, Sin, Zhu & Barbic 2015).

:class:`Energy` holds a user's energy (a full ``W(s1, s2, s3)`` or the separable ``f, g, h``),
:mod:`.parse` reads it without evaluation into SymPy, :mod:`.codegen` differentiates it once and
generates the compiled kernels every material uses. The material record is
:class:`femkit.solids.materials.EnergyMaterial`. SymPy and numba are imported on first use.
"""

from .parse import parse_energy
from .spec import Energy, RestModuli

__all__ = ["Energy", "RestModuli", "parse_energy"]
