"""Run the row of three holes fired together and with delays, and compare them (README.md).

    python examples/delay_blast/compare.py --out out/delay_blast
"""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
CASES = {"simultaneous": "scenario_simultaneous.toml", "delayed 0/25/50 µs": "scenario_delayed.toml"}


def run(out: Path) -> dict:
    from blastfrac.scenario import load_scenario
    from blastfrac.simulation import Simulation

    res = {}
    for name, f in CASES.items():
        d = out / f.replace("scenario_", "").replace(".toml", "")
        sc = load_scenario(HERE / f, ["simulation.progress=false"])
        sim = Simulation(sc, out_dir=d)
        s = sim.run(progress=False)
        res[name] = {"dir": str(d), "summary": s}
    return res


def table(res: dict) -> list[dict]:
    rows = []
    for name, r in res.items():
        s = r["summary"]
        fd, fr, vib = s["fracture_degree"], s["fragmentation"], s["vibration"]
        rows.append({
            "case": name, "D": fd["D"], "D_tensile": fd["D_tensile"], "D_shear": fd["D_shear"],
            "D burden": fd["burden:D"], "D between holes": fd["between_holes:D"], "D behind": fd["behind:D"],
            "fragments off the rock mass": fr["blasted_fragments"], "x50 [mm]": 1e3 * fr["x50"], "x80 [mm]": 1e3 * fr["x80"],
            "PPV max [m/s]": vib["ppv_max"], "PPV beta": vib["attenuation"]["beta"],
            "budget error": s["energy"]["budget_error_relative"], "wall [s]": s["wall_time_s"]})
    return rows


def figures(res: dict, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from blastfrac.analysis.fragments import passing_curve

    from PIL import Image, ImageChops

    crops = []
    for r in res.values():            # each run's own fracture_pattern.png, white margins cropped, stacked
        im = Image.open(Path(r["dir"]) / "fracture_pattern.png").convert("RGB")
        crops.append(im.crop(ImageChops.difference(im, Image.new("RGB", im.size, (255, 255, 255))).getbbox()))
    panel = Image.new("RGB", (max(c.width for c in crops), sum(c.height for c in crops) + 10), "white")
    y = 0
    for c in crops:
        panel.paste(c, (0, y))
        y += c.height + 10
    panel.save(HERE / "compare_patterns.png")

    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2), dpi=130)
    for name, r in res.items():
        d = Path(r["dir"])
        with open(d / "fragments.csv") as fh:
            rows = list(csv.DictReader(fh))
        size = np.array([float(x["size [m]"]) for x in rows])
        area = np.array([float(x["area [m^2]"]) for x in rows])
        off = np.array([x["touches_outer_boundary [-]"] == "0" for x in rows])
        if off.any():
            x, P = passing_curve(size[off], area[off])
            ax[0].step(1e3 * x, 100 * P, where="post", label=f"{name}: {off.sum()} fragments")
        with open(d / "ppv_profile.csv") as fh:
            pr = list(csv.DictReader(fh))
        ax[1].loglog([1e3 * float(p["radius [m]"]) for p in pr], [float(p["ppv_median [m/s]"]) for p in pr], "o-",
                     ms=3, label=name)
    ax[0].set_xscale("log")
    ax[0].set_xlabel("fragment size 2√(A/π) [mm]")
    ax[0].set_ylabel("passing [%] (fragments off the rock mass)")
    ax[1].set_xlabel("distance from the nearest hole [mm]")
    ax[1].set_ylabel("ring median of the PPV [m/s]")
    for a in ax:
        a.grid(alpha=0.3, which="both")
        a.legend(fontsize=8)
    fig.suptitle("Three holes near a free face: fired together against fired at 0/25/50 µs", fontsize=10)
    fig.tight_layout()
    fig.savefig(HERE / "compare_fragments_ppv.png")
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4), dpi=130)
    for name, r in res.items():
        with open(Path(r["dir"]) / "fracture_degree.csv") as fh:
            rows = list(csv.DictReader(fh))
        t = [1e6 * float(x["time [s]"]) for x in rows]
        for zone, ls in (("burden", "-"), ("behind", "--")):
            ax.plot(t, [float(x[f"{zone}:D [-]"]) for x in rows], ls, label=f"{name}, {zone}")
    for d in (25, 50):
        ax.axvline(d, color="0.6", lw=0.8, ls=":")
    ax.set_xlabel("time [µs]")
    ax.set_ylabel("fracture degree [-]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(HERE / "compare_fracture_degree.png")
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", default="out/delay_blast")
    out = Path(ap.parse_args().out)
    res = run(out)
    rows = table(res)
    (HERE / "compare.json").write_text(json.dumps(rows, indent=1))
    figures(res, out)
    keys = list(rows[0])
    print(" | ".join(keys))
    for r in rows:
        print(" | ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in r.values()))


if __name__ == "__main__":
    main()
