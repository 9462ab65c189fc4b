"""MPM explosive throughput: particle-steps per second at several particle counts.

A square PETN charge (2 x 2 points per cell) initiated at its centre, full MUSL steps
(P2G, grid update, G2P + remap + kinematics, burn, JWL).  Not a test: run
``python benchmarks/bench_mpm.py [--device cpu] [--steps N]``.
The scaling slope is d log(wall) / d log(n) over the sizes (1 = linear).
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def _solver(n_particles: int, device: str):
    from blastfrac.scenario.explosive import ExplosiveConfig
    from blastfrac.mpm import MPMSolver

    side_cells = int(round(np.sqrt(n_particles) / 2))
    h = 1e-3
    half = side_cells * h / 2
    cfg = ExplosiveConfig(
        name="petn",
        charges=[{"kind": "polygon", "vertices": [(-half, -half), (half, -half), (half, half), (-half, half)]}],
        grid={"cell_size": h, "margin": 0.25 * half},
    )
    return MPMSolver(cfg, device=device)


def timer(n_particles: int, device: str = "cpu"):
    """(info, block): the benchmark's charge of about ``n_particles`` points, one step run (kernel load);
    ``block(steps)`` runs that many more steps and returns their wall time [s], the device synchronised."""
    import warp as wp

    s = _solver(n_particles, device)
    dt = s.stable_dt()
    s.step(dt, 0.0)  # warm-up (kernel load)
    wp.synchronize_device(s.device)
    t = [dt]

    def block(steps: int) -> float:
        t0 = time.perf_counter()
        for _ in range(steps):
            s.step(dt, t[0])
            t[0] += dt
        wp.synchronize_device(s.device)
        return time.perf_counter() - t0

    return {"n_particles": s.n, "units": s.n}, block


def run(sizes=(100_000, 400_000, 1_600_000), steps: int = 20, device: str = "cpu", reps: int = 5) -> list[dict]:
    """Time ``reps`` consecutive blocks of ``steps`` steps per size and keep the median block (as the compiled
    reference times itself); returns dicts n_particles, steps, wall_s (the median block), reps, spread (slowest
    block over the fastest), particle_steps_per_s."""
    out = []
    for n in sizes:
        info, block = timer(n, device)
        walls = [block(steps) for _ in range(max(1, reps))]
        wall = float(np.median(walls))
        out.append({"n_particles": info["n_particles"], "steps": steps, "wall_s": wall, "reps": len(walls),
                    "spread": max(walls) / min(walls), "particle_steps_per_s": info["n_particles"] * steps / wall})
    return out


def run_grid_size(widths=(0.06, 0.12, 0.24, 0.48), steps: int = 100, device: str = "cpu") -> list[dict]:
    """A fixed small charge in ever larger grids: the cost of the active node box against the full-grid loops.

    The demo's charge (emulsion, radius 5 mm, 0.5 mm cells = 20 across, 2 x 2 points per cell) centred in a
    square grid of side ``widths`` [m]; ``steps`` MUSL steps after 20 of warm-up, timed once with the active
    box and once with the box widened to the whole grid (what every node loop cost before).  Returns dicts
    width_m, grid_nodes, box_nodes, particles, box_ms_per_step, full_ms_per_step.
    """
    import warp as wp

    import blastfrac.mpm.grid as grid_mod
    from blastfrac.mpm import MPMSolver
    from blastfrac.scenario.explosive import ExplosiveConfig

    out = []
    margin0 = grid_mod.BOX_MARGIN
    for w in widths:
        row = {"width_m": w}
        for label, margin in (("box", margin0), ("full", 10**9)):
            grid_mod.BOX_MARGIN = margin
            try:
                cfg = ExplosiveConfig(name="emulsion", charges=[{"kind": "circle", "center": (0, 0), "radius": 0.005}],
                                      grid={"cell_size": 5e-4, "points_per_cell": 2,
                                            "bounds": ((-w / 2, -w / 2), (w / 2, w / 2))})
                s = MPMSolver(cfg, device=device)
                t, dt = 0.0, s.stable_dt()
                for _ in range(20):
                    s.step(dt, t)
                    t += dt
                wp.synchronize_device(s.device)
                t0 = time.perf_counter()
                for _ in range(steps):
                    s.step(dt, t)
                    t += dt
                wp.synchronize_device(s.device)
                row[f"{label}_ms_per_step"] = 1e3 * (time.perf_counter() - t0) / steps
                row["grid_nodes"], row["particles"] = s.spec.node_count, s.n
                if label == "box":
                    row["box_nodes"] = s.grid.box_node_count
            finally:
                grid_mod.BOX_MARGIN = margin0
        out.append(row)
    return out


def scaling_slope(rows: list[dict]) -> float:
    """Least-squares slope of log(wall per step) against log(n)."""
    n = np.log([r["n_particles"] for r in rows])
    w = np.log([r["wall_s"] / r["steps"] for r in rows])
    return float(np.polyfit(n, w, 1)[0])


def grid_size_markdown(rows: list[dict]) -> str:
    lines = ["| grid side [mm] | grid nodes | box nodes | particles | box [ms/step] | full grid [ms/step] | full / box |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['width_m'] * 1e3:.0f} | {r['grid_nodes']:,} | {r['box_nodes']:,} | {r['particles']:,} | "
                     f"{r['box_ms_per_step']:.3f} | {r['full_ms_per_step']:.3f} | "
                     f"{r['full_ms_per_step'] / r['box_ms_per_step']:.2f} |")
    return "\n".join(lines)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--sizes", type=int, nargs="*", default=[100_000, 400_000, 1_600_000])
    a = ap.parse_args()
    rows = run(tuple(a.sizes), a.steps, a.device)
    print(f"{'particles':>10} {'steps':>6} {'wall [s]':>9} {'particle-steps/s':>17}")
    for r in rows:
        print(f"{r['n_particles']:>10d} {r['steps']:>6d} {r['wall_s']:>9.3f} {r['particle_steps_per_s']:>17.3e}")
    if len(rows) > 1:
        print(f"scaling slope d log(wall)/d log(n) = {scaling_slope(rows):.3f}")
    print(grid_size_markdown(run_grid_size(device=a.device)))
