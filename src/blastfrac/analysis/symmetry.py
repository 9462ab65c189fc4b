"""How the results of a half or quarter model read (geometry.symmetry): summary.json → ``symmetry``.

A half or quarter model is the part of a symmetric blast on one side of its symmetry lines (docs/explosive.md,
"Half and quarter models"). Everything the run reports is of the modelled part:

* counts (elements, springs, broken springs, particles, fragments) and energies [J/m] are the modelled part's;
  for the whole blast multiply them by ``mirror_factor`` = 2 per symmetry line (2 for a half model, 4 for a
  quarter model: the whole blast is the modelled part and its mirror images);
* the charge per hole of the vibration law (summary.json → vibration) is the whole hole's: the modelled charge
  divided by its modelled fraction (``charges[].modelled_fraction``);
* fracture degrees are ratios (broken springs over the springs of a zone) and read the same as in the full
  model; a zone that crosses a line is the modelled part of that zone;
* the borehole-wall pressure (borehole_pressure.csv) is the mean over the modelled wall: it needs no scaling;
* radial cracks (summary.json → cracks): the roller holds a symmetry line shut, so no crack opens *along* it;
  every other crack has its mirror image in the part not modelled, so the whole hole has about 2 × (half) or
  4 × (quarter) N_rad cracks. A crack that would run on the line in the full model is not there: it is counted
  once in the full model and not at all in the cut one (the cracks next to the line take its load);
* fragments: a fragment that touches a symmetry line is half of a fragment of the full model (its mirror image
  is the other half); it counts as touching the outer boundary.
"""

from __future__ import annotations

import math

READING = ("results are of the modelled part: multiply counts and energies by mirror_factor for the whole blast; "
           "fracture degrees and the wall pressure need no scaling; no crack opens along a symmetry line (the "
           "roller holds it shut), each other crack has a mirror image (docs/explosive.md, 'Half and quarter models')")


def symmetry_report(scenario) -> dict | None:
    """summary.json → symmetry: the lines, the modelled fraction of each borehole and charge, and the factor from
    the modelled part to the whole blast; None without geometry.symmetry."""
    from ..mpm.seeding import Cut, disc_cut_area

    g = scenario.geometry
    lines = g.symmetry_lines()
    if not lines:
        return None
    cuts = [Cut(axis, c, sign) for _, axis, c, sign in lines]
    holes = []
    for i, b in enumerate(g.boreholes):
        holes.append({"borehole": i, "cut_by": g.cut_sides(i),
                      "modelled_fraction": disc_cut_area(b.center, b.radius, cuts) / (math.pi * b.radius**2)})
    out = {"sides": list(g.symmetry),
           "lines": {side: {"xy"[axis]: c} for side, axis, c, _ in lines},
           "boreholes": holes}
    ex = scenario.explosive
    if ex is not None and ex.charges:
        out["charges"] = [{"charge": i, "modelled_fraction": charge_mirror_fraction(ch, lines)}
                          for i, ch in enumerate(ex.charges)]
    # the whole blast is the modelled part and its mirror images in each line: 2 (half) or 4 (quarter) copies
    out["mirror_factor"] = 2 ** len(lines)
    out["reading"] = READING
    return out


def charge_mirror_fraction(charge, lines) -> float:
    """Modelled area over whole area of a charge cut by symmetry ``lines`` (GeometryConfig.symmetry_lines)."""
    from ..mpm.seeding import charge_area_centroid, cut_charges

    return charge_area_centroid(cut_charges([charge], lines)[0])[0] / charge_area_centroid(charge)[0]


def describe(geometry) -> str:
    """One line for `blastfrac check`: the model's kind, its lines and the boreholes they cut."""
    from ..mpm.seeding import Cut, disc_cut_area

    lines = geometry.symmetry_lines()
    kind = {1: "half model", 2: "quarter model"}.get(len(lines), f"{len(lines)} symmetry lines")
    cuts = [Cut(axis, c, sign) for _, axis, c, sign in lines]
    text = f"{kind}: " + ", ".join(f"{side} ({'xy'[axis]} = {c:.6g} m)" for side, axis, c, _ in lines)
    text += " (roller on the rock, slip wall on the MPM grid)"
    cut = [f"hole{i} by {'+'.join(geometry.cut_sides(i))} "
           f"({disc_cut_area(b.center, b.radius, cuts) / (math.pi * b.radius**2):.3g} modelled)"
           for i, b in enumerate(geometry.boreholes) if geometry.cut_sides(i)]
    if cut:
        text += "; cut: " + ", ".join(cut)
    return text + "; results are of the modelled part (summary.json -> symmetry)"
