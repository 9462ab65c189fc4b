"""``blastfrac bench``: the performance suite (CDEM and MPM throughput, scaling slopes)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path


def add_parser(sub) -> None:
    p = sub.add_parser("bench", help="run the performance benchmarks (throughput, scaling)")
    p.add_argument("--device", default="cpu", help="cpu, cuda or cuda:N")
    p.add_argument("--steps", type=int, default=20, help="timed steps per size")
    p.add_argument("--quick", action="store_true", help="small sizes only (smoke run)")
    p.add_argument("--only", choices=("cdem", "mpm", "examples", "coupled"), default=None,
                   help="one suite; default: cdem and mpm ('examples' runs the paper's examples at full resolution, "
                   "minutes; 'coupled' times the demo, confined P0 and confined P0 with crack gas whole and per stage, "
                   "intact and cracked, on 1 and 2 cores)")
    p.add_argument("--two-core-steps", type=int, default=1500, metavar="N",
                   help="with --only coupled: time the shipped confined P0 over N steps on one core and on two "
                        "threads (0: skip)")
    p.add_argument("--reference", default=None, metavar="DIR",
                   help="also build the C++ reference of DIR (../shared/bench-reference) in a scratch copy and run "
                        "its CDEM and MPM loops on one thread beside blastfrac's, as ratios per element-step")
    p.set_defaults(func=run)


def _load(name: str):
    """Import benchmarks/<name>.py from the source tree (the suite is not installed with the package)."""
    root = Path(__file__).resolve().parents[3] / "benchmarks"
    path = root / f"{name}.py"
    if not path.is_file():
        from ..scenario import ScenarioError

        raise ScenarioError(f"benchmark suite not found at {root} (run from a source checkout)")
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def run(args) -> int:
    from .._warp import resolve_device
    from ..scenario import ScenarioError

    try:
        device = resolve_device(args.device)
    except ValueError as e:
        raise ScenarioError(f"--device: {e}") from None
    if args.only in (None, "cdem"):
        cdem = _load("bench_cdem")
        sizes = (5_000, 20_000) if args.quick else (50_000, 200_000, 800_000)
        rows = cdem.run(sizes, args.steps, device)
        print(f"CDEM on {device} (float64, all rock terms on)")
        print("| elements | springs | steps | wall [s] (median block) | blocks slowest / fastest | element-steps/s |")
        for r in rows:
            print(f"| {r['elements']:,} | {r['springs']:,} | {r['steps']} | {r['wall_s']:.3f} | {r['spread']:.2f} "
                  f"| {r['element_steps_per_s']:.3e} |")
        print(f"scaling slope: {cdem.scaling_slope(rows, 'elements'):.3f}\n")
    if args.only in (None, "mpm"):
        mpm = _load("bench_mpm")
        sizes = (10_000, 40_000) if args.quick else (100_000, 400_000, 1_600_000)
        rows = mpm.run(sizes, args.steps, device)
        print(f"MPM on {device} (float64, full MUSL step)")
        print("| particles | steps | wall [s] (median block) | blocks slowest / fastest | particle-steps/s |")
        for r in rows:
            print(f"| {r['n_particles']:,} | {r['steps']} | {r['wall_s']:.3f} | {r['spread']:.2f} "
                  f"| {r['particle_steps_per_s']:.3e} |")
        print(f"scaling slope: {_load('bench_cdem').scaling_slope(rows, 'n_particles'):.3f}")
        widths = (0.06, 0.24) if args.quick else (0.06, 0.12, 0.24, 0.48)
        print(f"\nMPM active node box on {device}: the demo's charge (1,257 points, 0.5 mm cells) in larger grids")
        print(mpm.grid_size_markdown(mpm.run_grid_size(widths, steps=max(args.steps, 50), device=device)))
    if args.only == "coupled":
        cp = _load("bench_coupled")
        rows = []
        for name in cp.CASES:
            r = cp.run_case(name, device, steps=max(args.steps, 50))
            r["one_core_wall_s"] = cp.one_core_wall(name, device) if device == "cpu" else None
            rows.append(r)
        print(f"Coupled step on {device} (outputs off)")
        print(cp.markdown(rows))
        fx = cp.fixed_cost(device)
        print(f"\nFixed cost of a step (the demo's step on {fx['tiny_size'][0]} elements and {fx['tiny_size'][1]} points, "
              f"one thread): {fx['tiny_ms']:.3f} ms, {100 * fx['fraction']:.0f} % of the demo's first steps "
              f"({fx['demo_ms']:.3f} ms); with threads = 2 {fx['tiny_2threads_ms']:.3f} ms (a step uses the second "
              f"thread only where the run's trial measured it faster); replayed from a captured graph "
              f"(simulation.graph = 'on') {fx['tiny_graph_ms']:.3f} ms ({fx['tiny_graph_replayed']} of "
              f"{50 + fx['steps']} steps replayed)")
        tc = cp.two_cores(args.two_core_steps, device) if args.two_core_steps > 0 else None
        if tc is not None:
            print(f"\nShipped confined P0 ({tc['elements']:,} blocks), {tc['steps']} steps after 20: one core "
                  f"(threads = 1, taskset) {1e3 * tc['one_core_s']:.2f} ms/step, two threads "
                  f"{1e3 * tc['two_threads_s']:.2f} ms/step: {tc['speedup']:.2f}x (threads chosen by the two-thread "
                  f"run's trials: {tc.get('trials_chose')})")
    if args.reference:
        cp = _load("bench_coupled")
        from pathlib import Path as _P

        ref = cp.run_reference(_P(args.reference), steps=args.steps, device=device)
        print("\nblastfrac against the compiled reference (same machine, same run, one thread)")
        print(cp.reference_markdown(ref))
    if args.only == "examples":
        ex = _load("bench_examples")
        rows = ex.run(device=device)
        print(ex.markdown(rows, device))
    sys.stdout.flush()
    return 0
