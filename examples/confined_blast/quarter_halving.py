"""Issue 11 item 3 on the quarter model: the confined blast P = 0 with the whole mesh halved, with and without the
fracture band.

    python examples/confined_blast/quarter_halving.py run [CASE ...] [--out out/quarter_far]
    python examples/confined_blast/quarter_halving.py table [--out out/quarter_far]

The quarter model (examples/symmetry/scenario_P0_quarter.toml, x ≥ 0, y ≥ 0; examples/symmetry/README.md shows it
reproduces the full model's wall load, fracture degree, crack count and length within the scatter of two meshes)
makes a full halving affordable: the shipped mesh (1 mm at the wall, 2.5 mm beyond the refinement zone, as
scenario_P0.toml) against 0.5 / 1.25 mm, ~2 and ~15 min on one core. Cases (name → overrides):

* ``ship`` / ``half``: the example's law; ``far`` / ``band_far``: the wall mesh kept, the far mesh halved only;
* ``band_ship`` / ``band_half``: with ``rock.fracture_band_width = 1 mm`` (docs/scenario.md, "Fracture band": an
  interface between blocks thinner than 1 mm carries the share h̄/w_c of the fracture energies);
* ``*_x101``: the same with every mesh size × 1.01, a second mesh of the same size (the noise floor).

``run`` runs the cases one after the other on one thread each (skipping those done); ``table`` prints the crack
statistics of summary.json, the cracked fraction and cracked length per area in 2.5 mm rings (all cracked
interfaces; areas from the blocks, so the quarter's rings are quarter rings), the damaged-zone radius r_d
(docs/results.md), the changes of the halved meshes,
and writes ``quarter_halving.png`` (the cracks within 70 mm: red tensile and blue shear of the hole's network,
grey detached) into this folder.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from blastfrac.analysis.cracks import zone_radii

HERE = Path(__file__).parent
SCENARIO = HERE.parent / "symmetry" / "scenario_P0_quarter.toml"
SHIP = ["geometry.mesh_size=0.0025", "geometry.mesh_size_near=0.001"]
HALF = ["geometry.mesh_size=0.00125", "geometry.mesh_size_near=0.0005"]
FAR = ["geometry.mesh_size=0.00125", "geometry.mesh_size_near=0.001"]
BAND = ["rock.fracture_band_width=0.001"]


def _x101(sizes: list[str]) -> list[str]:
    return [f"{s.split('=')[0]}={float(s.split('=')[1]) * 1.01:.7g}" for s in sizes]


#: name → overrides; the directory names are those of the runs this study was made from
CASES: dict[str, tuple[str, list[str]]] = {
    "ship": ("h0.0025", SHIP),
    "far": ("h0.00125", FAR),
    "half": ("h0.00125_n0.0005", HALF),
    "band_ship": ("band_h0.0025", SHIP + BAND),
    "band_half": ("band_h0.00125_n0.0005", HALF + BAND),
    "band_far": ("band_h0.00125", FAR + BAND),
    "ship_x101": ("h0.0025_x1.01", _x101(SHIP)),
    "band_ship_x101": ("band_h0.0025_x1.01", _x101(SHIP) + BAND),
    "band_half_x101": ("band_h0.00125_n0.0005_x1.01", _x101(HALF) + BAND),
}
#: (halved, shipped) pairs the table compares
PAIRS = (("half", "ship"), ("far", "ship"), ("band_half", "band_ship"), ("band_far", "band_ship"), ("band_half_x101", "band_ship_x101"),
         ("ship_x101", "ship"), ("band_ship_x101", "band_ship"), ("band_half_x101", "band_half"))
R_B = 0.005
RING = 0.0025


def run(names: list[str], out: Path) -> None:
    sys.path.insert(0, str(HERE))
    from mesh_objectivity import run_case

    for name in names:
        d, overrides = CASES[name]
        run_case(name, SCENARIO, out / d, ["simulation.progress=false", "simulation.threads=1"] + overrides)


def numbers(d: Path) -> dict:
    s = json.loads((d / "summary.json").read_text())
    c = s["cracks"][0]
    z = zone_radii(c)            # the study's r_c was the rule now called r_k; the tip is measured from r_k
    return {"blocks": s["counts"]["elements"], "rc": z["dense_cracking_radius_over_rb"],
            "rc_new": z["crushed_zone_radius_over_rb"], "longest": 1e3 * c["longest_radial_crack"],
            "tip": 1e3 * (c["longest_radial_crack"] + z["dense_cracking_radius"]),
            "n_rad": c["radial_crack_count"], "conn": c["connected_crack_length"], "total": c["crack_length_total"],
            "r90": 1e3 * c["crack_extent_r90"], "detached": c["detached_crack_sets"], "D": s["fracture_degree"]["D"],
            "wall": s["wall_time_s"]}


COLS = (("blocks", "blocks", "{:d}"), ("rc", "r_k/r_b", "{:.2f}"), ("rd", "r_d/r_b", "{:.2f}"), ("longest", "longest from r_k [mm]", "{:.1f}"),
        ("tip", "its tip from the centre [mm]", "{:.1f}"), ("n_rad", "N_rad (quarter)", "{:d}"),
        ("conn", "connected length [m]", "{:.2f}"), ("total", "all cracks [m]", "{:.2f}"), ("r90", "r90 [mm]", "{:.0f}"),
        ("detached", "detached sets", "{:d}"), ("D", "D", "{:.4f}"), ("wall", "wall [s]", "{:.0f}"))


def profiles(d: Path) -> dict:
    """Cracked fraction and cracked length per area [1/m] in RING-wide rings from the wall, and the crack segments
    within 70 mm (reference positions [m]) by kind, from the run's last ParaView frame."""
    sys.path.insert(0, str(HERE))
    from mesh_objectivity import final_mode

    from blastfrac.analysis.cracks import blast_cracked, connected_network, damaged_zone_radius

    b, mode = final_mode(d)
    X = b.host["node_X"]
    pn = b.topology.pair_nodes
    a, c = X[pn[0::2, 0]], X[pn[1::2, 0]]
    cracked = blast_cracked(b, mode)
    connected = connected_network(b, cracked, np.zeros(2), R_B)["connected"]
    tensile = (mode.reshape(-1, 2) == 1).any(axis=1)
    length = np.linalg.norm(c - a, axis=1)
    r = np.linalg.norm(0.5 * (a + c), axis=1)
    centroid = (X[0::3] + X[1::3] + X[2::3]) / 3.0
    e1, e2 = X[1::3] - X[0::3], X[2::3] - X[0::3]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    rc = np.linalg.norm(centroid, axis=1)
    edges = np.arange(R_B, 0.0601, RING)
    frac, dens = [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        ring = (r >= lo) & (r < hi)
        frac.append(float(cracked[ring].mean()))
        dens.append(float(length[ring & cracked].sum() / area[(rc >= lo) & (rc < hi)].sum()))
    near = np.maximum(np.abs(a).max(axis=1), np.abs(c).max(axis=1)) < 0.07
    seg = {k: np.stack([a[m & near], c[m & near]], 1) for k, m in
           (("detached", cracked & ~connected), ("tensile", connected & tensile), ("shear", connected & ~tensile))}
    rd = damaged_zone_radius(r, cracked, R_B)[0] / R_B       # also in summary.json of runs made since it was added
    return {"edges": edges, "fraction": frac, "density": dens, "segments": seg, "rd": rd}


def table(out: Path) -> None:
    rows = {n: numbers(out / d) for n, (d, _) in CASES.items() if (out / d / "summary.json").exists()}
    prof = {n: profiles(out / CASES[n][0]) for n in rows}
    for n in rows:
        rows[n]["rd"] = prof[n]["rd"]
    print("| case | " + " | ".join(c[1] for c in COLS) + " |")
    print("|---|" + "---:|" * len(COLS))
    for n, r in rows.items():
        print(f"| {n} | " + " | ".join(f.format(r[k]) for k, _, f in COLS) + " |")
    print("\nchanges [%] (first against second):")
    keys = ("rc", "rd", "longest", "tip", "conn", "total", "r90", "D")
    print("| pair | " + " | ".join(keys) + " |")
    for a, b in PAIRS:
        if a in rows and b in rows:
            print(f"| {a} vs {b} | " + " | ".join(f"{100 * (rows[a][k] / rows[b][k] - 1):+.0f}" for k in keys) + " |")
    e = next(iter(prof.values()))["edges"] if prof else []
    for what, fmt in (("fraction", "{:.2f}"), ("density", "{:.0f}")):
        print(f"\ncracked {'fraction' if what == 'fraction' else 'length per area [1/m]'} in {RING * 1e3:.1f} mm rings "
              f"from {R_B * 1e3:.0f} mm (ring starts [mm]: " + ", ".join(f"{1e3 * x:.1f}" for x in e[:-1][::2]) + ", every "
              "second):")
        for n, p in prof.items():
            print(f"| {n} | " + " | ".join(fmt.format(v) for v in p[what][::2]) + " |")
    figure(rows, prof)


def figure(rows: dict, prof: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    names = [n for n in ("ship", "half", "band_ship", "band_half") if n in prof]
    if not names:
        return
    fig, ax = plt.subplots(1, len(names) + 1, figsize=(4.6 * (len(names) + 1), 4.8), squeeze=False)
    for a, n in zip(ax[0], names):
        for kind, col in (("detached", "0.65"), ("tensile", "#d62728"), ("shear", "#1f77b4")):
            a.add_collection(LineCollection(1e3 * prof[n]["segments"][kind], colors=col, linewidths=0.6))
        a.set_xlim(0, 70)
        a.set_ylim(0, 70)
        a.set_aspect("equal")
        a.set_xlabel("x [mm]")
        r = rows[n]
        a.set_title(f"{n} ({r['blocks']:,} blocks)\nr_k/r_b {r['rc']:.2f}, r_d/r_b {r['rd']:.2f}, longest crack tip at {r['tip']:.0f} mm",
                    fontsize=9)
    a = ax[0][-1]
    for n, ls in zip(names, ("-", "--", "-", "--")):
        col = "k" if not n.startswith("band") else "#2ca02c"
        mid = 0.5e3 * (prof[n]["edges"][:-1] + prof[n]["edges"][1:])
        a.plot(mid, prof[n]["fraction"], ls, color=col, label=f"{n}: r_d = {prof[n]['rd']:.2f} r_b")
        a.axvline(1e3 * R_B * prof[n]["rd"], ls=ls, color=col, lw=0.7)
    a.axhline(0.5, color="0.6", lw=0.8)
    a.set_xlabel("r [mm]")
    a.set_ylabel(f"cracked fraction of the interfaces, {RING * 1e3:.1f} mm rings")
    a.legend(fontsize=8)
    a.set_title("black: the example's law; green: fracture band 1 mm\nvertical: damaged-zone radius r_d", fontsize=9)
    fig.tight_layout()
    fig.savefig(HERE / "quarter_halving.png", dpi=90)
    print(f"wrote {HERE / 'quarter_halving.png'}")


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("what", choices=("run", "table"))
    p.add_argument("cases", nargs="*")
    p.add_argument("--out", type=Path, default=Path("out/quarter_far"))
    a = p.parse_args(argv)
    if a.what == "run":
        run(a.cases or list(CASES), a.out)
    else:
        table(a.out)


if __name__ == "__main__":
    main()
