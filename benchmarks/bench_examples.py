"""Wall time of the shipped examples at full resolution (issue: paper examples on 2 CPU cores or a GPU).

Each scenario runs as shipped (outputs included, into a temporary folder); the table gives the counts, the
steps, the wall time of the run loop (summary.json → wall_time_s, in-situ stage included) and the rock
throughput in element-steps per second.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

EXAMPLES = (
    "examples/circular_rock/scenario.toml",
    "examples/single_hole/scenario.toml",
    "examples/confined_blast/scenario_P0.toml",
    "examples/confined_blast/scenario_P15.toml",
    "examples/confined_blast/scenario_P30.toml",
)


def run(paths=EXAMPLES, device: str = "cpu", root: Path | None = None) -> list[dict]:
    from blastfrac.scenario.load import load_scenario
    from blastfrac.simulation import Simulation

    root = root or Path(__file__).resolve().parents[1]
    rows = []
    for p in paths:
        sc = load_scenario(root / p)
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            s = Simulation(sc, out_dir=tmp, device=device).run(progress=False)
            total = time.perf_counter() - t0
        c = s["counts"]
        rows.append({"example": p, "elements": c["elements"], "springs": c["springs"], "particles": c["particles"],
                     "steps": s["steps"], "simulated_us": s["simulated_time"] * 1e6, "wall_s": s["wall_time_s"],
                     "total_s": total, "element_steps_per_s": s["element_steps_per_s"],
                     "insitu_steps": (s.get("insitu_stage") or {}).get("steps", 0)})
    return rows


def markdown(rows: list[dict], device: str) -> str:
    out = [f"Examples on {device} (as shipped, outputs on; wall = run loop incl. in-situ stage, total = with set-up)",
           "| example | elements | springs | particles | in-situ steps | steps | simulated [µs] | wall [s] | total [s] "
           "| element-steps/s |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        out.append(f"| {r['example']} | {r['elements']:,} | {r['springs']:,} | {r['particles']:,} | {r['insitu_steps']:,} "
                   f"| {r['steps']:,} | {r['simulated_us']:.0f} | {r['wall_s']:.1f} | {r['total_s']:.1f} "
                   f"| {r['element_steps_per_s']:.3e} |")
    return "\n".join(out)
