"""Compare the confined-blast runs P = 0, 15, 30 MPa (Yue et al. 2022, Figs. 9–11) from their output folders.

    python examples/confined_blast/compare.py [RUN_P0 RUN_P15 RUN_P30] [--out DIR]

Defaults: out/confined_blast_P0, _P15, _P30 (what the three scenarios write) and this folder for the figures.
Writes ``compare_patterns.png`` (Fig. 9), ``compare_monitor.png`` (Fig. 10), ``compare_fracture_degree.png``
(Fig. 11) and ``compare.json`` (the numbers quoted in the README), and prints a table.
"""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from blastfrac.analysis.cracks import zone_radii

HERE = Path(__file__).parent
PRESSURES = (0, 15, 30)
TENSILE, SHEAR = "#d62728", "#1f77b4"


def read_csv(path: Path) -> dict[str, np.ndarray]:
    with open(path) as f:
        rows = list(csv.reader(f))
    rows = [r for r in rows if r and not r[0].startswith("#")]
    head, data = rows[0], np.array(rows[1:], float)
    # headers carry units, 'm50mm:sxx [Pa]': key the columns by the bare name
    return {k.split(" [")[0].strip(): data[:, i] for i, k in enumerate(head)}


def run_numbers(run: Path) -> dict:
    """Key numbers of one run: monitor peaks, fracture degree by part at the end, crack statistics."""
    s = json.loads((run / "summary.json").read_text())
    mon = read_csv(run / "monitors.csv")
    fd = read_csv(run / "fracture_degree.csv")
    sxx = mon["m50mm:sxx"]
    d_sxx = sxx - sxx[0]                              # change from the pre-blast (in-situ) state
    parts = {f"part{k}": {m: float(fd[f"part{k}:{m}"][-1]) for m in ("D", "D_tensile", "D_shear")}
             for k in range(1, 11)}
    horiz = np.mean([parts[f"part{k}"]["D"] for k in range(1, 6)])
    vert = np.mean([parts[f"part{k}"]["D"] for k in range(6, 11)])
    c = s["cracks"][0]
    ins = s.get("insitu_stage") or {}
    return {
        "sxx_initial": float(sxx[0]),
        "radial_stress_compressive_peak": float(-d_sxx.min()),
        "radial_stress_tensile_peak": float(d_sxx.max()),
        "total_sxx_min": float(sxx.min()), "total_sxx_max": float(sxx.max()),
        "D": s["fracture_degree"]["D"], "D_tensile": s["fracture_degree"]["D_tensile"],
        "D_shear": s["fracture_degree"]["D_shear"], "parts": parts,
        "D_horizontal_mean": float(horiz), "D_vertical_mean": float(vert),
        # r_c by the rule of 2026-12-06 (NaN for older runs), and r_k, which older runs called r_c (docs/results.md)
        **{k: v for k, v in zone_radii(c).items() if k.endswith("_over_rb")},
        "damaged_zone_radius_over_rb": c.get("damaged_zone_radius_over_rb", float("nan")),  # runs since stop 26
        "radial_crack_count": c["radial_crack_count"], "longest_radial_crack": c["longest_radial_crack"],
        "insitu_broken": (ins.get("broken_tensile", 0) + ins.get("broken_shear", 0)) if ins else 0,
        "insitu_softening": ins.get("softening", 0) if ins else 0,
        "budget_error_relative": s["energy"]["budget_error_relative"],
        "wall_time_s": s["wall_time_s"], "steps": s["steps"], "elements": s["counts"]["elements"],
        "particles": s["counts"]["particles"],
    }


def figure_patterns(runs: list[Path], out: Path) -> None:
    fig, axes = plt.subplots(1, len(runs), figsize=(5 * len(runs), 5.2), dpi=150)
    for ax, run, p in zip(np.atleast_1d(axes), runs, PRESSURES):
        ax.imshow(plt.imread(run / "fracture_pattern.png"))
        ax.set_title(f"P = {p} MPa (vertical)", fontsize=11)
        ax.axis("off")
    fig.suptitle("Confined blast: fracture patterns at 90 µs (tensile red, shear blue); cf. Yue et al. Fig. 9")
    fig.tight_layout()
    fig.savefig(out / "compare_patterns.png")
    plt.close(fig)


def figure_monitor(runs: list[Path], out: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), dpi=150)
    for run, p in zip(runs, PRESSURES):
        mon = read_csv(run / "monitors.csv")
        t = mon["time"] * 1e6
        axes[0].plot(t, -mon["m50mm:sxx"] / 1e6, label=f"P = {p} MPa")
        axes[1].plot(t, mon["m50mm:pressure"] / 1e6, label=f"P = {p} MPa")
    axes[0].set_ylabel("radial stress −σxx at (50 mm, 0) [MPa], compression +")
    axes[1].set_ylabel("pressure −(σxx + σyy)/2 at (50 mm, 0) [MPa]")
    for ax in axes:
        ax.set_xlabel("time [µs]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Monitor point 50 mm from the hole along x (perpendicular to the stress); cf. Yue et al. Fig. 10")
    fig.tight_layout()
    fig.savefig(out / "compare_monitor.png")
    plt.close(fig)


def figure_fracture_degree(nums: list[dict], out: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), dpi=150, sharey=True)
    for ax, ks, name in ((axes[0], range(1, 6), "parts 1–5, along x (⊥ stress)"),
                         (axes[1], range(6, 11), "parts 6–10, along y (∥ stress)")):
        xs = np.arange(len(ks))
        for j, (n, p) in enumerate(zip(nums, PRESSURES)):
            dt = [n["parts"][f"part{k}"]["D_tensile"] for k in ks]
            ds = [n["parts"][f"part{k}"]["D_shear"] for k in ks]
            off = (j - 1) * 0.27
            ax.bar(xs + off, dt, 0.25, color=TENSILE, alpha=0.45 + 0.25 * j, label=f"tensile, P = {p}")
            ax.bar(xs + off, ds, 0.25, bottom=dt, color=SHEAR, alpha=0.45 + 0.25 * j, label=f"shear, P = {p}")
        ax.set_xticks(xs, [f"part {k}" for k in ks])
        ax.set_title(name, fontsize=10)
        ax.grid(alpha=0.3, axis="y")
    axes[0].set_ylabel("fracture degree at 90 µs [-]")
    axes[1].legend(fontsize=7, ncol=3)
    fig.suptitle("Fracture degree per part (bars: P = 0, 15, 30 MPa left to right); cf. Yue et al. Fig. 11")
    fig.tight_layout()
    fig.savefig(out / "compare_fracture_degree.png")
    plt.close(fig)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="*", type=Path,
                    default=[Path(f"out/confined_blast_P{p}") for p in PRESSURES])
    ap.add_argument("--out", type=Path, default=HERE)
    a = ap.parse_args(argv)
    if len(a.runs) != 3:
        ap.error("give the three run folders, P = 0, 15, 30 MPa in this order")
    nums = [run_numbers(r) for r in a.runs]
    a.out.mkdir(parents=True, exist_ok=True)
    figure_patterns(a.runs, a.out)
    figure_monitor(a.runs, a.out)
    figure_fracture_degree(nums, a.out)
    (a.out / "compare.json").write_text(json.dumps(dict(zip([f"P{p}" for p in PRESSURES], nums)), indent=1))
    print(f"{'':34s}" + "".join(f"{f'P = {p} MPa':>14s}" for p in PRESSURES))
    rows = [("in-situ: springs broken / softening", lambda n: f"{n['insitu_broken']} / {n['insitu_softening']}"),
            ("radial-stress compressive peak [MPa]", lambda n: f"{n['radial_stress_compressive_peak'] / 1e6:.1f}"),
            ("radial-stress tensile peak [MPa]", lambda n: f"{n['radial_stress_tensile_peak'] / 1e6:.1f}"),
            ("fracture degree D (tensile/shear)", lambda n: f"{n['D']:.3f} ({n['D_tensile']:.3f}/{n['D_shear']:.3f})"),
            ("mean D parts 1-5 (along x)", lambda n: f"{n['D_horizontal_mean']:.3f}"),
            ("mean D parts 6-10 (along y)", lambda n: f"{n['D_vertical_mean']:.3f}"),
            ("crushed zone r_c/r_b", lambda n: f"{n['crushed_zone_radius_over_rb']:.2f}"),
            ("dense cracking r_k/r_b", lambda n: f"{n['dense_cracking_radius_over_rb']:.2f}"),
            ("damaged zone r_d/r_b", lambda n: f"{n['damaged_zone_radius_over_rb']:.2f}"),
            ("radial cracks (max N(R))", lambda n: f"{n['radial_crack_count']}"),
            ("longest radial crack [mm]", lambda n: f"{n['longest_radial_crack'] * 1e3:.0f}"),
            ("energy budget error", lambda n: f"{n['budget_error_relative']:.2%}"),
            ("wall time [s]", lambda n: f"{n['wall_time_s']:.0f}")]
    for name, f in rows:
        print(f"{name:34s}" + "".join(f"{f(n):>14s}" for n in nums))


if __name__ == "__main__":
    main()
