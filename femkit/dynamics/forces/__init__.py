"""Forces a mass-spring scene may declare (springs and dashpots live in the system itself)."""

from .barrier import BarrierContact
from .base import Force
from .contact import GroundContact, SphereContact
from .gravity import Gravity
from .rayleigh import RayleighDamping
from .viscous import ViscousDamping

__all__ = ["Force", "BarrierContact", "Gravity", "ViscousDamping", "RayleighDamping", "GroundContact", "SphereContact"]
