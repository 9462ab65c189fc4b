"""Explosive library (JWL sets with sources) and the CJ consistency report."""

from blastfrac.explosives.library import EXPLOSIVES, cj_report, get_explosive

__all__ = ["EXPLOSIVES", "cj_report", "get_explosive"]
