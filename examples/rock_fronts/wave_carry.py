"""Does each shipped blast mesh carry its outgoing wave? (issue 11, item 6)

Each case runs its example unbreakable (``rock.unbreakable = true``: the springs never fail, the gas still loads
the wall) with +x monitors averaged over discs, and sets beside each monitor the converged elastic answer to the
run's own measured wall pressure: ``blastfrac.analysis.radial_wave`` (1D axisymmetric plane strain, dr = 0.02 mm,
the same disc averages, the same free outer radius, so the reflection from the free face is in both). The rock of
the reference is the block assembly's own (summary.json "elastic" / "assembly": E and ν of the blocks and springs
together, which per-area springs make softer than the input rock), so a difference is the mesh's, not the springs'.

    python examples/rock_fronts/wave_carry.py [demo demo_6mm circular circular_4mm circular_2.5mm single_hole ...]

Runs go to out/wave_carry/<case>/ (skipped when their summary.json exists); the table is printed and written to
out/wave_carry/table_<cases>.md.
"""

from __future__ import annotations

import argparse
import csv
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]

#: case: (scenario, monitor radii [m], averaging radius [m], outer radius [m] or None (fixed far boundary), overrides)
CASES = {
    "demo": ("examples/circular_rock/demo.toml", (0.02, 0.04, 0.06, 0.08, 0.1), 0.005, 0.11, []),
    "demo_6mm": ("examples/circular_rock/demo.toml", (0.02, 0.04, 0.06, 0.08, 0.1), 0.005, 0.11,
                 ["geometry.mesh_size=0.006"]),                  # the demo's far mesh until 2026-12-02
    "circular": ("examples/circular_rock/scenario.toml", (0.02, 0.04, 0.06, 0.08, 0.1), 0.005, 0.11,
                 ["simulation.end_time=3e-5"]),
    "circular_4mm": ("examples/circular_rock/scenario.toml", (0.02, 0.04, 0.06, 0.08, 0.1), 0.005, 0.11,
                     ["simulation.end_time=3e-5", "geometry.mesh_size=0.004"]),   # shipped until 2026-12-02
    "circular_2.5mm": ("examples/circular_rock/scenario.toml", (0.02, 0.04, 0.06, 0.08, 0.1), 0.005, 0.11,
                       ["simulation.end_time=3e-5", "geometry.mesh_size=0.0025"]),
    "single_hole": ("examples/single_hole/scenario.toml", (0.01, 0.02, 0.03, 0.04, 0.05, 0.06), 0.003, 0.072, []),
    "confined_ship": ("examples/confined_blast/scenario_P0.toml", (0.025, 0.05, 0.1, 0.2), 0.005, None,
                      ["geometry.mesh_size=0.01"]),
    "confined_farq": ("examples/confined_blast/scenario_P0.toml", (0.025, 0.05, 0.1, 0.2), 0.005, None, []),
}
BASE = ["simulation.progress=false", "rock.unbreakable=true", "output.paraview=false", "output.figures=false",
        "output.monitor_interval=2e-7"]


def _table(path: Path) -> dict[str, np.ndarray]:
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    head = [k.split(" [")[0] for k in rows[0]]
    return {k: np.array(rows[1:], float)[:, i] for i, k in enumerate(head)}


def run_case(name: str, out: Path, threads: int) -> Path:
    scen, radii, a, _, extra = CASES[name]
    d = out / name
    if (d / "summary.json").exists():
        return d
    d.mkdir(parents=True, exist_ok=True)
    text = (ROOT / scen).read_text()
    for r in radii:
        text += (f'\n[[monitors]]\nname = "w{r * 1000:g}"\nposition = [{r}, 0.0]\nquantities = ["sxx", "syy"]\n'
                 f"radius = {a}\n")
    s = d / "scenario_wave.toml"
    s.write_text(text)
    cmd = [str(Path(sys.executable).with_name("blastfrac")), "run", str(s), "--out", str(d)]
    for o in BASE + extra + [f"simulation.threads={threads}"]:
        cmd += ["--set", o]
    subprocess.run(cmd, check=True)
    return d


def compare(name: str, d: Path) -> list[tuple]:
    """Rows (r [m], 2D min σ_rr, 1D min σ_rr, 2D max σ_θθ, 1D max σ_θθ) [Pa] of one finished case."""
    from blastfrac.analysis.radial_wave import radial_wave
    from blastfrac.scenario import load_scenario

    _, radii, a, r_out, _ = CASES[name]
    mon = _table(d / "monitors.csv")
    bp = _table(d / "borehole_pressure.csv")
    sc = load_scenario(d / "resolved.toml")
    asm = json.loads((d / "summary.json").read_text())["elastic"]["assembly"]
    ref = radial_wave(bp["time"], bp["hole0"], sc.geometry.boreholes[0].radius, asm["youngs_modulus"],
                      asm["poisson_ratio"], sc.rock.density, [], t_end=float(mon["time"][-1]), dr=2e-5,
                      r_out=r_out, discs=[(r, a) for r in radii])
    rows = []
    for k, r in enumerate(radii):
        key = f"w{r * 1000:g}"
        rows.append((r, mon[f"{key}:sxx"].min(), ref.disc_sxx[:, k].min(), mon[f"{key}:syy"].max(),
                     ref.disc_syy[:, k].max()))
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("cases", nargs="*", default=["demo", "circular", "single_hole"], choices=list(CASES))
    p.add_argument("--out", type=Path, default=Path("out/wave_carry"))
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--table-only", action="store_true", help="compare the finished runs, run nothing")
    args = p.parse_args()
    lines = ["| case | r [mm] | min σrr 2D / 1D [MPa] | error | max σθθ 2D / 1D [MPa] | error |", "|---|---:|---:|---:|---:|---:|"]
    for name in args.cases:
        d = args.out / name if args.table_only else run_case(name, args.out, args.threads)
        for r, c2, c1, t2, t1 in compare(name, d):
            lines.append(f"| {name} | {r * 1000:g} | {c2 / 1e6:.0f} / {c1 / 1e6:.0f} | {c2 / c1 - 1:+.0%} | "
                         f"{t2 / 1e6:+.0f} / {t1 / 1e6:+.0f} | {t2 / t1 - 1:+.0%} |")
    print("\n".join(lines))
    (args.out / ("table_" + "_".join(args.cases) + ".md")).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
