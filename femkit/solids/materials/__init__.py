"""Materials as energies of the principal stretches (see :mod:`.base`)."""

from .base import Material, StretchMaterial, lame_from_young
from .designed import EnergyMaterial, designed
from .builtin_materials import (MATERIALS, Corotational, LinearElastic, StableNeoHookean, StVenantKirchhoff,
                       material)
from .spec import material_from_spec

__all__ = ["Material", "StretchMaterial", "lame_from_young", "MATERIALS", "LinearElastic",
           "Corotational", "StVenantKirchhoff", "StableNeoHookean", "material", "EnergyMaterial",
           "designed", "material_from_spec"]
