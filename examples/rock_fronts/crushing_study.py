"""Crushed-zone radius of a small coupled blast against the springs' compressive cap (rock.crushing_strength).

The blast is that of tests/verification/test_coupled_blast.py: a 3 mm hole full of the paper's emulsion in a
12 cm square of its Table 2 rock (UCS 171.6 MPa by Mohr–Coulomb) with non-reflecting sides, 20 µs, the shipped
examples' blast damping and fracture energies. For each cap σ_cr = factor × UCS (0: no cap, the paper's law) and
mesh scale (1: h = r_b/5 at the wall and the MPM cell; 2: both halved) it prints r_c/r_b against the bracket of
VALIDATION §4 (Esen et al. 2003 to power-law attenuation to the UCS), the connected radial-crack count, the
longest crack and the broken springs by mode, and writes crushing_study.md.

Run: python examples/rock_fronts/crushing_study.py [--factors 0 1 2 4 8] [--scales 1 2] [--out DIR]
(about 25 s per case at scale 1 and 45 s at scale 2 on 2 cores)
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parents[1] / "tests" / "verification")]

from test_coupled_blast import ROCK, crushed_zone_bracket, small_blast  # noqa: E402

from blastfrac.simulation import Simulation  # noqa: E402

UCS = 2 * ROCK["cohesion"] * math.cos(math.radians(ROCK["friction_angle"])) / (
    1 - math.sin(math.radians(ROCK["friction_angle"])))


def blast(factor: float, scale: float, out: Path) -> dict:
    sc = small_blast({"crushing_strength": factor * UCS} if factor > 0 else None, scale=scale, paraview=False)
    s = Simulation(sc, out_dir=out).run()
    c = s["cracks"][0]
    # rc: the rule this study was made with (now the dense-cracking radius r_k); rc_crushed: r_c of 2026-12-06
    return {"factor": factor, "scale": scale, "rc": c["dense_cracking_radius_over_rb"],
            "rc_crushed": c["crushed_zone_radius_over_rb"], "radial": c["radial_crack_count"],
            "longest_mm": c["longest_radial_crack"] * 1e3, "broken": s["broken_springs"]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--factors", type=float, nargs="+", default=[0, 1, 2, 4, 8])
    ap.add_argument("--scales", type=float, nargs="+", default=[1, 2])
    ap.add_argument("--out", type=Path, default=Path("out/crushing_study"))
    a = ap.parse_args()
    lo, hi = crushed_zone_bracket()
    rows = [f"Bracket r_c/r_b {lo:.2f} (Esen) – {hi:.2f} (power law to the UCS); UCS {UCS / 1e6:.1f} MPa.", "",
            "| σ_cr / UCS | mesh | r_c / r_b (broken in every direction) | r_k / r_b (the former r_c) | radial cracks | "
            "longest [mm] | tensile / shear / crushed springs |",
            "|---:|---:|---:|---:|---:|---:|---|"]
    for f in a.factors:
        for sc in a.scales:
            r = blast(f, sc, a.out / f"cap{f:g}_scale{sc:g}")
            b = r["broken"]
            rows.append(f"| {'none' if f == 0 else f'{f:g}'} | h/{sc:g} | {r['rc_crushed']:.2f} | {r['rc']:.2f} | "
                        f"{r['radial']} | "
                        f"{r['longest_mm']:.1f} | {b['tensile']} / {b['shear']} / {b['crushed']} |")
            print(rows[-1], flush=True)
    (HERE / "crushing_study.md").write_text("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
