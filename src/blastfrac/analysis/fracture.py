"""Fracture degree: broken springs over all springs, split tensile/shear/crushed, globally and per zone.

A *spring* is one node pair of an interface (its normal and tangential parts break together),
so an interior edge holds two springs. Zone membership is decided by the spring's reference
position (the two nodes of a pair coincide initially). Per-zone degrees divide by the zone's
own spring count; the global-denominator variant divides by all springs (METHOD §4).

Pre-existing joints (geometry.joints) are not blast fracture: with ``exclude`` (the joint springs,
``model.host["pair_joint"] >= 0``, see :func:`joint_spring_mask`) they count in neither the numerator nor the
denominator of any degree, whether they were open from t = 0 or broke during the run (docs/joints.md).
"""

from __future__ import annotations

import numpy as np

from ..materials.interface import CRUSHED, SHEAR, TENSILE
from ..scenario.schema import AnnulusZone, RectangleZone, SectorZone


def zone_mask(zone, xy: np.ndarray) -> np.ndarray:
    """Boolean mask of the points xy [M, 2] inside ``zone``."""
    if isinstance(zone, RectangleZone):
        return (xy[:, 0] >= zone.xmin) & (xy[:, 0] < zone.xmax) & (xy[:, 1] >= zone.ymin) & (xy[:, 1] < zone.ymax)
    d = xy - np.asarray(zone.center)
    r = np.hypot(d[:, 0], d[:, 1])
    inside = (r >= zone.r_inner) & (r < zone.r_outer)
    if isinstance(zone, SectorZone):
        ang = np.degrees(np.arctan2(d[:, 1], d[:, 0]))
        a0 = zone.angle_start % 360.0
        span = (zone.angle_end - zone.angle_start) % 360.0 or 360.0
        inside &= ((ang - a0) % 360.0) < span
    return inside


class FractureDegree:
    """Counts broken springs by mode in the whole model and in each zone."""

    def __init__(self, pair_xy: np.ndarray, zones: list, exclude: np.ndarray | None = None):
        """``exclude``: springs counted nowhere (the joints' springs), mask [P]; None: none."""
        self.keep = None if exclude is None or not np.any(exclude) else ~np.asarray(exclude, bool)
        self.total = len(pair_xy) if self.keep is None else int(self.keep.sum())
        self.zones = zones
        self.masks = [zone_mask(z, pair_xy) for z in zones]
        if self.keep is not None:
            self.masks = [m & self.keep for m in self.masks]
        self.zone_totals = [int(m.sum()) for m in self.masks]

    def _modes(self, mode: np.ndarray):
        tens, shear, crush = mode == TENSILE, mode == SHEAR, mode == CRUSHED
        if self.keep is not None:
            tens, shear, crush = tens & self.keep, shear & self.keep, crush & self.keep
        return tens, shear, crush

    def sample(self, mode: np.ndarray) -> dict[str, float]:
        """Fracture degrees from the spring mode array (0 intact, 1 tensile, 2 shear, 3 crushed: the compressive
        cap rock.crushing_strength, always 0 without it)."""
        tens, shear, crush = self._modes(mode)
        n = max(self.total, 1)
        row = {
            "D": (tens.sum() + shear.sum() + crush.sum()) / n,
            "D_tensile": tens.sum() / n,
            "D_shear": shear.sum() / n,
            "D_crushed": crush.sum() / n,
        }
        for z, m, nz in zip(self.zones, self.masks, self.zone_totals):
            den = max(nz, 1)
            broken = tens[m].sum() + shear[m].sum() + crush[m].sum()
            row[f"{z.name}:D"] = broken / den
            row[f"{z.name}:D_tensile"] = tens[m].sum() / den
            row[f"{z.name}:D_shear"] = shear[m].sum() / den
            row[f"{z.name}:D_crushed"] = crush[m].sum() / den
            row[f"{z.name}:D_global"] = broken / n
        return {k: float(v) for k, v in row.items()}

    def counts(self, mode: np.ndarray) -> dict[str, int]:
        tens, shear, crush = self._modes(mode)
        return {"total": self.total, "tensile": int(tens.sum()), "shear": int(shear.sum()),
                "crushed": int(crush.sum())}


def joint_spring_mask(model) -> np.ndarray | None:
    """The springs on pre-existing joints, mask [P], or None for a model without joints."""
    pj = model.host.get("pair_joint")
    return None if pj is None or not np.any(pj >= 0) else pj >= 0


def annular_zones(center, r_b: float, r_max: float) -> list[AnnulusZone]:
    """Doubling annuli [r_b, 2r_b), [2r_b, 4r_b), … up to r_max (METHOD §4)."""
    zones, r, i = [], r_b, 0
    while r < r_max:
        zones.append(AnnulusZone(name=f"annulus{i}", center=center, r_inner=r, r_outer=min(2 * r, r_max)))
        r, i = 2 * r, i + 1
    return zones
