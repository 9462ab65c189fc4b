"""The circular-rock example on three far meshes (issue 11, items 3 and 6): 4 mm (shipped until this study),
2.5 mm and 1.25 mm, the wall mesh (0.8 mm) unchanged. ``examples/rock_fronts/wave_carry.py circular
circular_fine`` measures how well the first two carry the outgoing wave; this runs the breakable example on all
three and prints the crack statistics side by side, with a figure of the three patterns.

    python examples/circular_rock/far_mesh.py [--out out/circular_far_mesh] [--threads 1]

Runs go to <out>/h<size>/ (skipped when their summary.json exists); the table is printed, the figure written to
<out>/far_mesh_patterns.png.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SIZES = (0.004, 0.0025, 0.00125, 0.0008)
ZONES = ("r5-10mm", "r10-20mm", "r20-40mm", "r40-80mm", "r80-110mm")


def numbers(d: Path) -> dict:
    s = json.loads((d / "summary.json").read_text())
    c, fd = s["cracks"][0], s["fracture_degree"]
    row = {"elements": s["counts"]["elements"], "wall": s["wall_time_s"], "rc": c["crushed_zone_radius_over_rb"],
           "rd": c.get("damaged_zone_radius_over_rb", float("nan")),                 # in runs since stop 26
           "n_rad": c["radial_crack_count"], "n_rad_r": 1e3 * c["radial_crack_count_radius"],
           "longest": 1e3 * c["longest_radial_crack"], "conn_len": c["connected_crack_length"],
           "total_len": c["crack_length_total"], "D": fd["D"], "budget": 100 * s["energy"]["budget_error_relative"]}
    row.update({z: fd[f"{z}:D"] for z in ZONES})
    return row


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, default=Path("out/circular_far_mesh"))
    p.add_argument("--threads", type=int, default=1)
    a = p.parse_args()
    rows = {}
    for h in SIZES:
        d = a.out / f"h{h * 1000:g}"
        if not (d / "summary.json").exists():
            cmd = [str(Path(sys.executable).with_name("blastfrac")), "run",
                   str(ROOT / "examples/circular_rock/scenario.toml"), "--out", str(d), "--set",
                   f"geometry.mesh_size={h}", "--set", f"simulation.threads={a.threads}", "--set",
                   "simulation.progress=false"]
            subprocess.run(cmd, check=True)
        rows[h] = numbers(d)
    head = ("far h [mm] | blocks | r_c/r_b | r_d/r_b | connected radial cracks (at R [mm]) | longest [mm] | connected length [m] |"
            " all cracks [m] | D | " + " | ".join(f"D {z}" for z in ZONES) + " | budget [%] | wall [s]")
    print("| " + head + " |")
    print("|" + "---:|" * (head.count("|") + 1))
    for h, r in rows.items():
        print(f"| {h * 1000:g} | {r['elements']} | {r['rc']:.2f} | {r['rd']:.2f} | {r['n_rad']} ({r['n_rad_r']:.0f}) | "
              f"{r['longest']:.0f} | {r['conn_len']:.2f} | {r['total_len']:.2f} | {r['D']:.3f} | "
              + " | ".join(f"{r[z]:.2f}" for z in ZONES) + f" | {r['budget']:.2f} | {r['wall']:.0f} |")
    pairs = list(rows)
    for coarse, fine in zip(pairs, pairs[1:]):
        a_, b_ = rows[coarse], rows[fine]
        print(f"{coarse * 1000:g} → {fine * 1000:g} mm: " + ", ".join(
            f"{k} {100 * (b_[k] / a_[k] - 1):+.0f} %" for k in ("rc", "rd", "n_rad", "longest", "conn_len", "total_len",
                                                                "D", *ZONES)))
    _figure(a.out, rows)


def _figure(out: Path, rows: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.image import imread

    fig, axes = plt.subplots(1, len(rows), figsize=(6 * len(rows), 6.3))
    for ax, (h, r) in zip(axes, rows.items()):
        ax.imshow(imread(out / f"h{h * 1000:g}" / "fracture_pattern.png"))
        ax.set_title(f"far mesh {h * 1000:g} mm: {r['elements']} blocks, r_c/r_b {r['rc']:.2f}, "
                     f"{r['n_rad']} connected radial cracks", fontsize=10)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(out / "far_mesh_patterns.png", dpi=60)
    print(f"figure: {out / 'far_mesh_patterns.png'}")


if __name__ == "__main__":
    main()
