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


def run(sizes=(100_000, 400_000, 1_600_000), steps: int = 20, device: str = "cpu") -> list[dict]:
    """Time ``steps`` MUSL steps per size; returns dicts n_particles, steps, wall_s, particle_steps_per_s."""
    import warp as wp

    out = []
    for n in sizes:
        s = _solver(n, device)
        dt = s.stable_dt()
        s.step(dt, 0.0)  # warm-up (kernel load)
        wp.synchronize_device(s.device)
        t0 = time.perf_counter()
        t = dt
        for _ in range(steps):
            s.step(dt, t)
            t += dt
        wp.synchronize_device(s.device)
        wall = time.perf_counter() - t0
        out.append({"n_particles": s.n, "steps": steps, "wall_s": wall, "particle_steps_per_s": s.n * steps / wall})
    return out


def scaling_slope(rows: list[dict]) -> float:
    """Least-squares slope of log(wall per step) against log(n)."""
    n = np.log([r["n_particles"] for r in rows])
    w = np.log([r["wall_s"] / r["steps"] for r in rows])
    return float(np.polyfit(n, w, 1)[0])


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
