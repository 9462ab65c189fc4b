"""Gas–rock coupling: particle–edge contact between the MPM explosive and the CDEM rock (METHOD §3)."""

from .coupler import GasRockCoupler, default_contact_stiffness
from .seeding import clear_from_rock

__all__ = ["GasRockCoupler", "default_contact_stiffness", "clear_from_rock"]
