"""CDEM throughput: element-steps per second with every rock term on, and its scaling with size.

A square of rock with a pressurised borehole, viscous sides, breakable springs and block
contact switched on (its spatial hash is rebuilt when a node has moved h_min/4, i.e. rarely here). Meshes of about 50k, 200k and 800k
triangles; the scaling slope is d log(time per step) / d log(elements).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np


def _scenario(n_elements: int):
    from blastfrac.scenario import scenario_from_dict

    side = 0.2
    # a uniform Delaunay mesh has about 2.3 triangles per h² of area
    h = side / math.sqrt(n_elements / 2.3)
    return scenario_from_dict({
        "simulation": {"progress": False},
        "rock": {"tensile_strength": 10e6, "cohesion": 40e6},
        "geometry": {"domain": {"type": "rectangle", "width": side, "height": side}, "mesh_size": h,
                     "boreholes": [{"radius": 0.005}]},
        "borehole_pressure": [{"borehole": 0, "pulse": {"type": "constant", "value": 50e6}}],
        "boundaries": {s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
    })


def timer(n_elements: int, device: str = "cpu"):
    """(info, block): the benchmark's model of about ``n_elements`` triangles, built and one step run (kernel load);
    ``block(steps)`` runs that many more steps and returns their wall time [s], the device synchronised."""
    import warp as wp

    from blastfrac._warp import init_warp
    from blastfrac.cdem.solver import CDEMSolver
    from blastfrac.model.builder import ModelBuilder

    init_warp()
    m = ModelBuilder(_scenario(n_elements)).finalize(device)
    st, solver = m.state(), CDEMSolver(m)
    solver.contact.active = True                  # all terms on, including the block-contact search
    dt = 0.8 * m.stable_dt
    solver.forces(st, dt, 0.0)                    # warm-up (kernel load)
    solver.integrate(st, dt)
    wp.synchronize_device(device)
    k = [1]

    def block(steps: int) -> float:
        t0 = time.perf_counter()
        for _ in range(steps):
            solver.forces(st, dt, k[0] * dt)
            solver.integrate(st, dt)
            k[0] += 1
        wp.synchronize_device(device)
        return time.perf_counter() - t0

    return {"elements": m.element_count, "springs": m.spring_count, "units": m.element_count}, block


def run(sizes=(50_000, 200_000, 800_000), steps: int = 20, device: str = "cpu", reps: int = 5) -> list[dict]:
    """Time ``reps`` consecutive blocks of ``steps`` steps per size and keep the median block (as the compiled
    reference times itself: a single block on a shared VM can be 1.5x off); ``spread`` is the slowest block over
    the fastest."""
    rows = []
    for n in sizes:
        info, block = timer(n, device)
        walls = [block(steps) for _ in range(max(1, reps))]
        wall = float(np.median(walls))
        rows.append({"elements": info["elements"], "springs": info["springs"], "steps": steps, "wall_s": wall,
                     "reps": len(walls), "spread": max(walls) / min(walls),
                     "element_steps_per_s": info["elements"] * steps / wall, "device": device})
    return rows


def scaling_slope(rows: list[dict], size_key: str) -> float:
    n = np.array([r[size_key] for r in rows], float)
    t = np.array([r["wall_s"] / r["steps"] for r in rows])
    return float(np.polyfit(np.log(n), np.log(t), 1)[0])


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--steps", type=int, default=20)
    p.add_argument("--device", default="cpu")
    p.add_argument("--sizes", type=int, nargs="+", default=[50_000, 200_000, 800_000])
    a = p.parse_args(argv)
    rows = run(tuple(a.sizes), a.steps, a.device)
    print("| elements | springs | steps | wall [s] | element-steps/s |")
    print("|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['elements']:,} | {r['springs']:,} | {r['steps']} | {r['wall_s']:.3f} | {r['element_steps_per_s']:.3e} |")
    if len(rows) > 1:
        print(f"\nscaling slope d log(t/step) / d log(elements) = {scaling_slope(rows, 'elements'):.3f}")


if __name__ == "__main__":
    main()
