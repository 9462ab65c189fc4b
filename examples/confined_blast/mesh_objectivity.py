"""Mesh objectivity of the confined blast P = 0 with heterogeneous rock (issue 11 item 3).

    python examples/confined_blast/mesh_objectivity.py run [CASE ...] [--out out/mesh_objectivity]
    python examples/confined_blast/mesh_objectivity.py table [--out out/mesh_objectivity]
    python examples/confined_blast/mesh_objectivity.py wave [--out out/mesh_objectivity]

``run`` runs the cases one at a time (each `blastfrac run examples/confined_blast/scenario_P0.toml` with the
overrides below, ParaView frames at 0 and 90 µs only), in the order listed, skipping those whose summary.json exists. ``table`` prints
the Markdown table of mesh_study.md ("Mesh objectivity with heterogeneous rock") from the summaries and writes
``mesh_objectivity_patterns.png`` (the fracture patterns, shipped above halved) into this folder, then the
cracked fraction of fixed 1.2 mm rings (and r_k/r_b at that width: the dense-cracking rule, the former r_c) and the
cracked length per area in annuli, from each run's last ParaView frame. ``wave`` runs the shipped and halved mesh with
unbreakable rock and monitors at 25–200 mm (with and without the shock viscosity, ~20 s and ~110 s each) and
prints the peak radial compression and hoop tension.

Cases: 'hom' = the example's homogeneous rock; 'iid' = Weibull m = 5 on T and c (correlated), one draw per
interface whatever its length; 'wl' = the same with weakest-link size scaling, reference_length 5 mm; 'wl3' =
'wl' with m = 3; 'cf' = Weibull m = 5 (T and c) spatially correlated over ℓ = 3 mm
(rock.heterogeneity.correlation_length), identical on both meshes for one seed; 'gv2'/'gvb' = the halved mesh
with G_fII (gv2) or both fracture energies (gvb) halved; 'fb12'/'fb25' = rock.fracture_band_width 1.2 / 2.5 mm;
'farq_near1' / 'farq_near05' = the quarter mesh's far size (2.5 mm) with the shipped / halved wall size.
'ship' = the mesh the example shipped until stop 23 (1 mm at the wall, mesh_size 10 mm), 'half' = mesh_size 5 mm and
mesh_size_near 0.5 mm (the MPM cell is 0.5 mm on both), 'quarter' = 2.5 mm and 0.25 mm (hom only; about 35 minutes
on 2 cores). 'farq_near1' is the example's mesh since stop 23 (mesh_size 2.5 mm).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from itertools import pairwise
from pathlib import Path

from blastfrac.analysis.cracks import zone_radii

HERE = Path(__file__).parent
SCENARIO = HERE / "scenario_P0.toml"
#: the mesh the example shipped until stop 23 (10 mm beyond the refinement zone), which every 'ship' case uses
SHIP = ["geometry.mesh_size=0.01"]
HALF = ["geometry.mesh_size_near=0.0005", "geometry.mesh_size=0.005", "explosive.grid.cell_size=0.0005"]
#: the halved mesh halved again (the convergence check of the halved mesh; the MPM cell stays 0.5 mm)
QUARTER = ["geometry.mesh_size_near=0.00025", "geometry.mesh_size=0.0025", "explosive.grid.cell_size=0.0005"]
M = 5.0
L_REF = 0.005
IID = [f"rock.heterogeneity.weibull_modulus={M}"]
WL = IID + [f"rock.heterogeneity.reference_length={L_REF}"]
#: the spatially correlated field (rock.heterogeneity.correlation_length): the same strengths at the same place
#: on both meshes, so one seed compares the meshes like with like
ELL = 0.003
CF = IID + [f"rock.heterogeneity.correlation_length={ELL}"]

#: name → overrides, in the order of the study (the most informative first)
CASES: dict[str, list[str]] = {
    "hom_ship": SHIP,
    "hom_half": HALF,
    "hom_quarter": QUARTER,
    "wl_ship_s0": SHIP + WL,
    "wl_half_s0": WL + HALF,
    "iid_ship_s0": SHIP + IID,
    "iid_half_s0": IID + HALF,
    "wl_ship_s1": SHIP + WL + ["simulation.seed=1"],
    "wl_ship_s2": SHIP + WL + ["simulation.seed=2"],
    "wl_half_s1": WL + HALF + ["simulation.seed=1"],
    "iid_ship_s1": SHIP + IID + ["simulation.seed=1"],
    "iid_half_s1": IID + HALF + ["simulation.seed=1"],
    "wl3_ship_s0": SHIP + [x.replace(f"={M}", "=3.0") for x in WL],
    "wl3_half_s0": [x.replace(f"={M}", "=3.0") for x in WL] + HALF,
    # the shipped energies halved on the halved mesh: what a fracture energy per unit volume would give
    "gv2_half": HALF + ["rock.shear_fracture_energy=250"],
    "gvb_half": HALF + ["rock.shear_fracture_energy=250", "rock.tensile_fracture_energy=25"],
    # the fracture band (rock.fracture_band_width): the share h̄/w_c of G_f on blocks thinner than w_c
    "fb12_ship": SHIP + ["rock.fracture_band_width=0.0012"],
    "fb12_half": HALF + ["rock.fracture_band_width=0.0012"],
    "fb25_ship": SHIP + ["rock.fracture_band_width=0.0025"],
    "fb25_half": HALF + ["rock.fracture_band_width=0.0025"],
    # a far mesh that carries the wave (2.5 mm everywhere beyond the refinement, as on the quarter mesh) with
    # the shipped (1 mm) or the halved (0.5 mm) wall mesh: the near-wall refinement alone
    "farq_near1": ["geometry.mesh_size=0.0025"],
    "farq_near05": ["geometry.mesh_size=0.0025", "geometry.mesh_size_near=0.0005"],
    "cf_ship_s0": SHIP + CF,
    "cf_half_s0": CF + HALF,
    "cf_ship_s1": SHIP + CF + ["simulation.seed=1"],
    "cf_half_s1": CF + HALF + ["simulation.seed=1"],
}


def run_case(name: str, scenario: Path, d: Path, overrides: list[str]) -> None:
    """``blastfrac run scenario --out d --set …`` in a subprocess, unless d holds a summary.json already."""
    if (d / "summary.json").exists():
        print(f"{name}: done already")
        return
    cmd = [str(Path(sys.executable).with_name("blastfrac")), "run", str(scenario), "--out", str(d)]
    for o in overrides:
        cmd += ["--set", o]
    print(" ".join(cmd), flush=True)
    t0 = time.time()
    subprocess.run(cmd, check=True)
    print(f"{name}: {time.time() - t0:.0f} s", flush=True)


def run(names: list[str], out: Path, threads: int = 2) -> None:
    # as measured: the study predates the example's fracture band (the fb cases set their own, after this)
    base = ["simulation.progress=false", "output.interval=9e-5", f"simulation.threads={threads}",
            "rock.fracture_band_width=0"]
    for name in names:
        run_case(name, SCENARIO, out / name, base + CASES[name])


def numbers(d: Path) -> dict:
    s = json.loads((d / "summary.json").read_text())
    c = s["cracks"][0]
    return {
        "elements": s["counts"]["elements"], "wall": s["wall_time_s"],
        # the r_c of this study is the rule now called the dense-cracking radius r_k (docs/results.md)
        "rc": zone_radii(c)["dense_cracking_radius_over_rb"], "n_rad": c["radial_crack_count"],
        "longest": 1e3 * c["longest_radial_crack"], "mean": 1e3 * c["mean_radial_crack_length"],
        "detached": c["detached_crack_sets"], "detached_long": c["detached_crack_sets_long"],
        "conn_len": c["connected_crack_length"], "total_len": c["crack_length_total"],
        "r50": 1e3 * c["crack_extent_r50"], "r80": 1e3 * c["crack_extent_r80"], "r90": 1e3 * c["crack_extent_r90"],
        "D": s["fracture_degree"]["D"], "budget": 100 * s["energy"]["budget_error_relative"],
    }


COLS = [("rc", "r_k/r_b", "{:.2f}"), ("longest", "longest [mm]", "{:.0f}"), ("mean", "mean [mm]", "{:.0f}"),
        ("n_rad", "N_rad", "{:d}"), ("detached", "detached sets (long)", "{:d}"), ("conn_len", "conn. length [m]", "{:.2f}"),
        ("total_len", "all cracks [m]", "{:.2f}"), ("r50", "r50 [mm]", "{:.0f}"), ("r80", "r80 [mm]", "{:.0f}"),
        ("r90", "r90 [mm]", "{:.0f}"), ("D", "D", "{:.3f}"), ("budget", "budget [%]", "{:+.2f}"),
        ("wall", "wall [s]", "{:.0f}")]


def table(out: Path) -> None:
    rows = {n: numbers(out / n) for n in CASES if (out / n / "summary.json").exists()}
    print("| run | elements | " + " | ".join(c[1] for c in COLS) + " |")
    print("|---|---:|" + "---:|" * len(COLS))
    for n, r in rows.items():
        cells = []
        for key, _, fmt in COLS:
            v = fmt.format(r[key])
            if key == "detached":
                v += f" ({r['detached_long']})"
            cells.append(v)
        print(f"| {n} | {r['elements']} | " + " | ".join(cells) + " |")
    print("\nhalved against shipped, quarter against halved [%]:")
    for n, b in rows.items():
        coarser = n.replace("_half", "_ship") if "_half" in n else n.replace("_quarter", "_half")
        if coarser == n or coarser not in rows:
            continue
        a = rows[coarser]
        print(f"| {n} vs {coarser} | " + " | ".join(f"{100 * (b[k] / a[k] - 1):+.0f}" for k, _, _ in COLS if k != "budget")
              + " |")
    patterns(out, rows)
    ring_table(out)


def patterns(out: Path, rows: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    hom = [n for n in ("hom_ship", "hom_half", "hom_quarter") if n in rows and (out / n / "fracture_pattern.png").exists()]
    if "hom_quarter" in hom:
        fig, ax = plt.subplots(1, len(hom), figsize=(5 * len(hom), 5.3), squeeze=False)
        for a, name in zip(ax[0], hom):
            a.axis("off")
            a.imshow(plt.imread(out / name / "fracture_pattern.png"))
            r = rows[name]
            a.set_title(f"{name} ({r['elements']} blocks): longest {r['longest']:.0f} mm, r90 {r['r90']:.0f} mm",
                        fontsize=9)
        fig.tight_layout()
        fig.savefig(HERE / "mesh_convergence_patterns.png", dpi=90)
        print(f"wrote {HERE / 'mesh_convergence_patterns.png'}")
    cols = [c for c in ("hom", "iid", "wl") if f"{c}_ship" in rows or f"{c}_ship_s0" in rows]
    if len(cols) < 3:                       # the shipped figure has all three: do not overwrite it with fewer
        return
    fig, ax = plt.subplots(2, len(cols), figsize=(5 * len(cols), 10), squeeze=False)
    for j, c in enumerate(cols):
        for i, mesh in enumerate(("ship", "half")):
            name = f"{c}_{mesh}" if c == "hom" else f"{c}_{mesh}_s0"
            a = ax[i][j]
            a.axis("off")
            png = out / name / "fracture_pattern.png"
            if png.exists():
                a.imshow(plt.imread(png))
                r = rows[name]
                a.set_title(f"{name}: longest {r['longest']:.0f} mm, detached {r['detached']}", fontsize=10)
    fig.tight_layout()
    fig.savefig(HERE / "mesh_objectivity_patterns.png", dpi=90)
    print(f"wrote {HERE / 'mesh_objectivity_patterns.png'}")


#: annuli [m] of the cracked-length density
DENSITY_EDGES = (0.005, 0.01, 0.02, 0.04, 0.06, 0.08, 0.1, 0.15, 0.2, 0.25)
#: fixed ring width for the crushed zone on both meshes: the shipped mesh's ring width (its wall mesh) [m]
RING = 0.0012


def final_mode(d: Path):
    """(model builder, pair mode [2Q]) of a run from its resolved.toml and last ParaView frame: the crack lines
    of the frame are node pairs (io.paraview.crack_segments), mapped back to the interfaces."""
    import meshio
    import numpy as np

    from blastfrac.model.builder import ModelBuilder
    from blastfrac.scenario import load_scenario

    b = ModelBuilder(load_scenario(d / "resolved.toml"))
    frames = sorted(d.glob("rock_*.vtu"))
    m = meshio.read(frames[-1])
    seg = np.concatenate([c.data for c in m.cells if c.type == "line"])
    cm = np.concatenate([v for c, v in zip(m.cells, m.cell_data["crack_mode"]) if c.type == "line"])
    pn = b.topology.pair_nodes
    key = {(int(i), int(j)): q for q, (i, j) in enumerate(zip(pn[0::2, 0], pn[1::2, 0]))}
    mode = np.zeros(len(pn), np.int32)
    for (i, j), c in zip(seg, cm):
        q = key[int(i), int(j)]
        mode[2 * q] = mode[2 * q + 1] = c
    return b, mode


def rings(d: Path, r_b: float = 0.005, width: float = RING, r_max: float = 0.04) -> dict:
    """Cracked fraction of the interfaces in rings of a fixed width [m] (both meshes alike) from the wall, and
    the radius r_c/r_b of this study (the dense-cracking radius of analysis.cracks) at that width."""
    import numpy as np

    from blastfrac.analysis.cracks import (
        blast_cracked,
        crack_statistics,
        dense_cracking_radius,
    )

    b, mode = final_mode(d)
    X = b.host["node_X"]
    pn = b.topology.pair_nodes
    r = np.linalg.norm(0.5 * (X[pn[0::2, 0]] + X[pn[1::2, 0]]), axis=1)
    cracked = blast_cracked(b, mode)
    edges = np.arange(r_b, r_max + 1e-12, width)
    frac = [float(cracked[(r >= a) & (r < a + width)].mean()) for a in edges[:-1]]
    coarse = [float(cracked[(r >= a) & (r < a + 0.005)].mean()) for a in np.arange(r_b, 0.05 - 1e-12, 0.005)]
    # cracked length per unit area [1/m] in annuli, all cracks and the shear-broken part (a length density is
    # what the weakest-link scaling keeps independent of the mesh, where an interface fraction is not)
    L = np.linalg.norm(X[pn[1::2, 0]] - X[pn[0::2, 0]], axis=1)
    shear = cracked & ~(mode.reshape(-1, 2) == 1).any(axis=1)
    dens = []
    for a, c in pairwise(DENSITY_EDGES):
        ring = (r >= a) & (r < c)
        area = np.pi * (c * c - a * a)
        dens.append((float(L[ring & cracked].sum() / area), float(L[ring & shear].sum() / area)))
    check = crack_statistics(b, mode, np.zeros(2), r_b)
    return {"rc_fixed": dense_cracking_radius(r, cracked, r_b, width) / r_b, "fractions": frac, "edges": edges.tolist(),
            "coarse": coarse, "density": dens,
            "rc_check": check["dense_cracking_radius_over_rb"], "longest_check": check["longest_radial_crack"]}


def ring_table(out: Path) -> None:
    print(f"\ncracked fraction [%] in rings of {RING * 1e3:.1f} mm from the wall (r_k/r_b at that width), and in 5 mm "
          "rings 5-10, ..., 45-50 mm:")
    dens = {}
    for n in CASES:
        d = out / n
        if not (d / "summary.json").exists() or not list(d.glob("rock_*.vtu")):
            continue
        r = rings(d)
        s = json.loads((d / "summary.json").read_text())["cracks"][0]
        assert abs(r["rc_check"] - zone_radii(s)["dense_cracking_radius_over_rb"]) < 1e-9, n   # frame = summary
        print(f"| {n} | {r['rc_fixed']:.2f} | " + " ".join(f"{100 * f:.0f}" for f in r["fractions"]) + " | "
              + " / ".join(f"{100 * f:.0f}" for f in r["coarse"]) + " |")
        dens[n] = r["density"]
    print("\ncracked length per area [1/m], all (shear) in the annuli "
          + ", ".join(f"{1e3 * a:.0f}-{1e3 * c:.0f}" for a, c in pairwise(DENSITY_EDGES)) + " mm:")
    for n, d in dens.items():
        print(f"| {n} | " + " | ".join(f"{a:.0f} ({b:.0f})" for a, b in d) + " |")


#: radii [mm] of the +x monitors of the wave check, and its cases (unbreakable rock; with/without shock viscosity)
WAVE_R = (25, 50, 75, 100, 150, 200)
WAVE = {"ship": SHIP, "half": HALF[:2], "farq": ["geometry.mesh_size=0.0025"],
        "ship_novisc": SHIP + ["rock.bulk_viscosity_linear=0", "rock.bulk_viscosity_quadratic=0"],
        "half_novisc": HALF[:2] + ["rock.bulk_viscosity_linear=0", "rock.bulk_viscosity_quadratic=0"]}


def wave(out: Path, names: list[str] | None = None) -> None:
    """The outgoing wave in unbreakable rock on both meshes: radial and hoop stress at +x monitors (5 mm
    averaging discs), peak compression and peak hoop tension per radius; beside each run the converged elastic
    answer to its own wall pressure (analysis/radial_wave.py: 1D axisymmetric, dr = 0.02 mm, the same 5 mm
    disc averages), so the table says how much of the pulse each mesh carries to each radius."""
    import csv

    import numpy as np

    from blastfrac.analysis.radial_wave import radial_wave
    from blastfrac.scenario import load_scenario

    names = names or list(WAVE)
    w = out / "wave"
    w.mkdir(parents=True, exist_ok=True)
    scen = w / "scenario_P0_monitors.toml"
    text = SCENARIO.read_text()
    for r in WAVE_R:
        text += (f'\n[[monitors]]\nname = "x{r}"\nposition = [{r / 1000}, 0.0]\nquantities = ["sxx", "syy"]\n'
                 "radius = 0.005\n")
    scen.write_text(text)
    base = ["simulation.progress=false", "rock.unbreakable=true", "output.paraview=false", "output.figures=false",
            "output.monitor_interval=2e-7"]
    for name in names:
        if not (w / name / "summary.json").exists():
            cmd = [str(Path(sys.executable).with_name("blastfrac")), "run", str(scen), "--out", str(w / name)]
            for o in base + WAVE[name]:
                cmd += ["--set", o]
            subprocess.run(cmd, check=True)

    def table(rows):
        with open(rows) as f:
            rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
        head = [k.split(" [")[0] for k in rows[0]]
        return {k: np.array(rows[1:], float)[:, i] for i, k in enumerate(head)}

    cols = []
    for name in names:
        d = table(w / name / "monitors.csv")
        bp = table(w / name / "borehole_pressure.csv")
        sc = load_scenario(w / name / "resolved.toml")
        rk = sc.rock
        ref = radial_wave(bp["time"], bp["hole0"], sc.geometry.boreholes[0].radius, rk.youngs_modulus,
                          rk.poisson_ratio, rk.density, [], t_end=float(bp["time"][-1]), dr=2e-5,
                          discs=[(r / 1000, 0.005) for r in WAVE_R])
        cols.append((name, d, ref))
    print("| r [mm] | " + " | ".join(f"{n}: min σrr / max σθθ [MPa] | 1D reference" for n, _, _ in cols) + " |")
    print("|---|" + "---|---|" * len(cols))
    for k, r in enumerate(WAVE_R):
        cells = []
        for _, d, ref in cols:
            cells.append(f"{d[f'x{r}:sxx'].min() / 1e6:.0f} / {d[f'x{r}:syy'].max() / 1e6:+.0f}")
            cells.append(f"{ref.disc_sxx[:, k].min() / 1e6:.0f} / {ref.disc_syy[:, k].max() / 1e6:+.0f}")
        print(f"| {r} | " + " | ".join(cells) + " |")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("action", choices=["run", "table", "wave"])
    p.add_argument("cases", nargs="*", help="cases to run (default: all, in order)")
    p.add_argument("--out", type=Path, default=Path("out/mesh_objectivity"))
    p.add_argument("--threads", type=int, default=2, help="simulation.threads of each run (1 to run two at once)")
    a = p.parse_args()
    if a.action == "run":
        run(a.cases or list(CASES), a.out, a.threads)
    elif a.action == "wave":
        wave(a.out, a.cases or None)
    else:
        table(a.out)


if __name__ == "__main__":
    main()
