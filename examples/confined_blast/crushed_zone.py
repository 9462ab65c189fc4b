"""Issue 11 item 3: is the rock about the hole crushed, and does the answer hold when the mesh is halved?

    python examples/confined_blast/crushed_zone.py RUN_DIR [RUN_DIR ...] [--pair A:B ...] [--figure PATH]

For each run directory (a `blastfrac run` output with ParaView frames; the confined examples and their quarter
models, hole of radius 5 mm at the origin) this reads the crack pattern of the last frame and prints, by the
definitions of docs/results.md:

* r_c, the crushed-zone radius (rings one wall mesh size wide from the wall, each with at least half of its radial
  *and* half of its circumferential interfaces cracked: rock broken in every direction);
* r_k, the dense-cracking radius (the same rings with half of *all* interfaces cracked: the rule r_c had until
  2026-12-06);
* r_d, the damaged-zone radius;
* the cracked fraction of each orientation class (radial: within 45° of the radius) in [r_b, 2 r_b) and [2, 3) r_b.

``--pair A:B`` prints the changes of A against B (by position in the list, e.g. 1:0 for the second run against
the first); ``--figure`` draws the cracked fraction of each class against r in rings of 1 mm (solid radial,
dashed circumferential, dotted line at r_c). The quantities are computed here with the present code from the
frame, so runs made before a change of the definitions read the same way as new ones.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
R_B = 0.005
RING = 0.001


def zones(d: Path) -> dict:
    """r_c, r_k, r_d (over r_b), the blocks, and the class-resolved cracked fractions of the run in ``d``."""
    sys.path.insert(0, str(HERE))
    from mesh_objectivity import final_mode

    from blastfrac.analysis.cracks import blast_cracked, crack_statistics, radial_interfaces

    b, mode = final_mode(d)
    s = crack_statistics(b, mode, np.zeros(2), R_B)
    X = b.host["node_X"]
    pn = b.topology.pair_nodes
    a, c = X[pn[0::2, 0]], X[pn[1::2, 0]]
    r = np.linalg.norm(0.5 * (a + c), axis=1)
    radial = radial_interfaces(a, c, np.zeros(2))
    cracked = blast_cracked(b, mode)

    def frac(lo, hi, cls):
        sel = cls & (r >= lo) & (r < hi)
        return float(cracked[sel].mean()) if sel.any() else float("nan")

    edges = np.arange(R_B, 5 * R_B + 1e-12, RING)
    return {"dir": str(d), "blocks": b.mesh.triangles.shape[0], "w_mm": 1e3 * s["ring_width"],
            "rc": s["crushed_zone_radius_over_rb"], "rk": s["dense_cracking_radius_over_rb"],
            "rd": s["damaged_zone_radius_over_rb"],
            "radial_1_2": frac(R_B, 2 * R_B, radial), "circ_1_2": frac(R_B, 2 * R_B, ~radial),
            "radial_2_3": frac(2 * R_B, 3 * R_B, radial), "circ_2_3": frac(2 * R_B, 3 * R_B, ~radial),
            "edges": edges, "radial": [frac(lo, hi, radial) for lo, hi in zip(edges[:-1], edges[1:])],
            "circ": [frac(lo, hi, ~radial) for lo, hi in zip(edges[:-1], edges[1:])]}


COLS = (("blocks", "blocks", "{:,}"), ("w_mm", "w [mm]", "{:.2f}"), ("rc", "r_c/r_b", "{:.2f}"),
        ("rk", "r_k/r_b", "{:.2f}"), ("rd", "r_d/r_b", "{:.2f}"), ("radial_1_2", "radial cracked, 1–2 r_b", "{:.2f}"),
        ("circ_1_2", "circumferential cracked, 1–2 r_b", "{:.2f}"), ("radial_2_3", "radial, 2–3 r_b", "{:.2f}"),
        ("circ_2_3", "circumferential, 2–3 r_b", "{:.2f}"))


def figure(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(10.5, 4.5), dpi=110)
    for i, z in enumerate(rows):
        col = f"C{i}"
        mid = 0.5 * (z["edges"][:-1] + z["edges"][1:]) / R_B
        name = Path(z["dir"]).name
        ax.plot(mid, z["radial"], "-", color=col, label=f"{name}: radial")
        ax.plot(mid, z["circ"], "--", color=col, label=f"{name}: circumferential (r_c/r_b = {z['rc']:.2f})")
        ax.axvline(z["rc"], color=col, ls=":", lw=1.0)
    ax.axhline(0.5, color="0.6", lw=0.8)
    ax.set_xlabel("r / r_b")
    ax.set_ylabel(f"cracked fraction of the class, {RING * 1e3:.0f} mm rings")
    ax.set_ylim(0, 1.02)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title("Crushed means broken in every direction: the radial interfaces crack, the circumferential ones\n"
                 "mostly do not (dotted: crushed-zone radius r_c)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    print(f"wrote {path}")


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("runs", nargs="+", type=Path)
    p.add_argument("--pair", action="append", default=[], help="A:B, the change of run A against run B (positions)")
    p.add_argument("--figure", type=Path, default=None)
    a = p.parse_args(argv)
    rows = [zones(d) for d in a.runs]
    print("| run | " + " | ".join(c[1] for c in COLS) + " |")
    print("|---|" + "---:|" * len(COLS))
    for z in rows:
        print(f"| {Path(z['dir']).name} | " + " | ".join(f.format(z[k]) for k, _, f in COLS) + " |")
    for pr in a.pair:
        i, j = (int(x) for x in pr.split(":"))
        print(f"{Path(rows[i]['dir']).name} against {Path(rows[j]['dir']).name}: "
              + ", ".join(f"{k} {100 * (rows[i][k] / rows[j][k] - 1):+.0f} %" for k in ("rc", "rk", "rd")))
    if a.figure:
        figure(rows, a.figure)


if __name__ == "__main__":
    main()
