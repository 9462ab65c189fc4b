"""Compare the confined blast (P = 0) with its half and quarter models: compare_symmetry.png and compare.json.

Run the three scenarios first (README.md), then:  python examples/symmetry/compare.py [FULL HALF QUARTER]
(output directories; default out/confined_blast_P0, out/symmetry_P0_half, out/symmetry_P0_quarter).

The cut models' cracks are drawn with their mirror images in the symmetry lines (x = 0; x = 0 and y = 0).
Wall load: borehole_pressure.csv re-binned into windows (the impulse between window edges over the window).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from blastfrac.analysis.cracks import zone_radii

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
NAMES = ("full", "half", "quarter")
DEFAULT = [ROOT / "out/confined_blast_P0", ROOT / "out/symmetry_P0_half", ROOT / "out/symmetry_P0_quarter"]
MIRRORS = {"full": [], "half": [(-1.0, 1.0)], "quarter": [(-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]}


def window_means(rows: np.ndarray, edges: np.ndarray) -> tuple[np.ndarray, float]:
    t, p = rows[:, 0], rows[:, 1]
    impulse = np.concatenate([[0.0], np.cumsum(p[1:] * np.diff(t))])
    return np.diff(np.interp(edges, t, impulse)) / np.diff(edges), float(impulse[-1])


def crack_lines(out: Path) -> tuple[np.ndarray, np.ndarray]:
    """(segments [n,2,2] m, mode [n]) of the last ParaView frame's crack lines."""
    import meshio

    last = sorted(out.glob("rock_*.vtu"))[-1]
    m = meshio.read(last)
    for k, c in enumerate(m.cells):
        if c.type == "line":
            seg = m.points[c.data][:, :, :2]
            return seg, np.asarray(m.cell_data["crack_mode"][k]).reshape(-1)
    return np.zeros((0, 2, 2)), np.zeros(0)


def main(dirs: list[Path]) -> dict:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    runs = {}
    for name, d in zip(NAMES, dirs):
        runs[name] = {"summary": json.loads((d / "summary.json").read_text()),
                      "wall": np.loadtxt(d / "borehole_pressure.csv", delimiter=",", skiprows=1),
                      "monitors": np.genfromtxt(d / "monitors.csv", delimiter=",", names=True),
                      "cracks": crack_lines(d)}
    T = runs["full"]["wall"][-1, 0]
    edges = np.arange(0.0, T + 1e-12, 1e-6)
    mean_f, imp_f = window_means(runs["full"]["wall"], edges)
    early = edges[1:] <= 10e-6
    report = {}
    for name, r in runs.items():
        s = r["summary"]
        mean, imp = window_means(r["wall"], edges)
        fd, c = s["fracture_degree"], s["cracks"][0]
        parts = [fd[f"part{i}:D"] for i in range(1, 11)]
        mirror = s.get("symmetry", {}).get("mirror_factor", 1) if s.get("symmetry") else 1
        report[name] = {
            "wall_time_s": round(s["wall_time_s"], 1), "steps": s["steps"], "elements": s["counts"]["elements"],
            "particles": s["counts"]["particles"], "ms_per_step": round(1e3 * s["wall_time_s"] / s["steps"], 2),
            "wall_impulse_rel": round(imp / imp_f - 1, 4),
            "wall_impulse_0_10us_rel": round(float(np.sum(mean[early]) / np.sum(mean_f[early]) - 1), 4),
            "wall_mean_1us_max_diff_of_peak": round(float(np.max(np.abs(mean - mean_f)) / mean_f.max()), 4),
            "D": round(fd["D"], 4), "D_tensile": round(fd["D_tensile"], 4), "D_shear": round(fd["D_shear"], 4),
            "mean_D_parts_1_5": round(float(np.mean(parts[:5])), 3), "mean_D_parts_6_10": round(float(np.mean(parts[5:])), 3),
            "radial_cracks": c["radial_crack_count"], "radial_cracks_whole": c["radial_crack_count"] * mirror,
            "crack_length_whole_m": round(c["crack_length_total"] * mirror, 2),
            **{k: round(v, 2) for k, v in zone_radii(c).items() if k.endswith("_over_rb")},
            "explosive_released_whole_J_per_m": round(s["energy"]["explosive_released"] * mirror),
            "ppv_K": round(s["vibration"]["attenuation"]["K"], 2), "ppv_beta": round(s["vibration"]["attenuation"]["beta"], 3),
        }
        r["mean"] = mean
        r["parts"] = parts
    fig, ax = plt.subplots(2, 3, figsize=(15, 9.5))
    lim = 0.13
    for k, (name, r) in enumerate(runs.items()):
        seg, mode = r["cracks"]
        segs, modes = [seg], [mode]
        for sx, sy in MIRRORS[name]:
            segs.append(seg * np.array([sx, sy]))
            modes.append(mode)
        seg, mode = np.concatenate(segs), np.concatenate(modes)
        col = np.where(mode == 1, "tab:red", "tab:blue")
        a = ax[0, k]
        a.add_collection(LineCollection(seg, colors=col, linewidths=0.7))
        if MIRRORS[name]:
            a.axvline(0.0, color="0.5", lw=0.8, ls="--")
            if name == "quarter":
                a.axhline(0.0, color="0.5", lw=0.8, ls="--")
        a.set_xlim(-lim, lim), a.set_ylim(-lim, lim), a.set_aspect("equal")
        a.set_title(f"{name}: {report[name]['radial_cracks_whole']} radial cracks (whole), D = {report[name]['D']:.3f}"
                    + ("\n(modelled part and its mirror images, dashed: symmetry lines)" if MIRRORS[name] else "\n"),
                    fontsize=10)
        a.set_xlabel("x [m]")
    ax[0, 0].set_ylabel("y [m]")
    mid = 0.5 * (edges[1:] + edges[:-1]) * 1e6
    for name, r in runs.items():
        ax[1, 0].plot(mid, r["mean"] / 1e6, label=f"{name} (impulse {report[name]['wall_impulse_rel']:+.1%})", lw=1.2)
        m = r["monitors"]
        ax[1, 1].plot(m[m.dtype.names[0]] * 1e6, m["m50mmsxx_Pa"] / 1e6, label=name, lw=1.0)
    ax[1, 0].set_xlabel("t [µs]"), ax[1, 0].set_ylabel("borehole-wall pressure, 1 µs means [MPa]")
    ax[1, 0].set_title("wall load (borehole_pressure.csv)", fontsize=10), ax[1, 0].legend(fontsize=9)
    ax[1, 1].set_xlabel("t [µs]"), ax[1, 1].set_ylabel("σxx at (50 mm, 0) [MPa]")
    ax[1, 1].set_title("monitor m50mm (on the quarter model's symmetry line)", fontsize=10), ax[1, 1].legend(fontsize=9)
    x = np.arange(1, 11)
    for j, (name, r) in enumerate(runs.items()):
        ax[1, 2].bar(x + (j - 1) * 0.27, r["parts"], width=0.27, label=name)
    ax[1, 2].set_xticks(x), ax[1, 2].set_xlabel("part (1-5 along x, 6-10 along y)")
    ax[1, 2].set_ylabel("fracture degree D"), ax[1, 2].set_title("fracture degree per strip at 90 µs", fontsize=10)
    ax[1, 2].legend(fontsize=9)
    fig.tight_layout()
    fig.savefig(HERE / "compare_symmetry.png", dpi=110)
    (HERE / "compare.json").write_text(json.dumps(report, indent=2) + "\n")
    return report


if __name__ == "__main__":
    args = [Path(a) for a in sys.argv[1:]]
    print(json.dumps(main(args if len(args) == 3 else DEFAULT), indent=2))
