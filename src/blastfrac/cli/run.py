"""``blastfrac run SCENARIO``: run a scenario and write its results."""

from __future__ import annotations

import sys

from .common import add_force_arg, add_scenario_args, check_output_dir, load, resolve_device


def add_parser(sub) -> None:
    p = sub.add_parser("run", help="run a scenario", description="Run a scenario and write results to its output directory.")
    add_scenario_args(p)
    p.add_argument("--out", default=None, help="output directory (default: output.directory of the scenario)")
    p.add_argument("--max-steps", type=int, default=None, help="stop after N steps of the dynamic stage")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_force_arg(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..scenario import ScenarioError
    from ..scenario.sizes import check_sizes
    from ..simulation import Simulation, SimulationError

    sc = load(args)
    if args.out:
        sc.output.directory = args.out
    check_output_dir(sc.output.directory, "--out" if args.out else "output.directory")
    if args.max_steps is not None and args.max_steps <= 0:
        raise ScenarioError("--max-steps must be a positive integer")
    resolve_device(sc, args)
    est = check_sizes(sc, force=args.force)
    if est.elements is not None and est.elements > 500_000:
        print(f"meshing about {est.elements:,} elements ({est.detail})", file=sys.stderr)
    try:
        sim = Simulation(sc, max_steps=args.max_steps)
    except ValueError as e:
        raise ScenarioError(str(e)) from None
    try:
        s = sim.run(progress=False if args.no_progress else None)
    except SimulationError as e:
        print(f"error: {e}", file=sys.stderr)   # summary.json (status 'failed') and the CSVs are written
        return 1
    b = s["broken_springs"]
    print(f"{s['steps']} steps, t = {s['simulated_time'] * 1e6:.2f} µs, wall {s['wall_time_s']:.1f} s; "
          f"broken springs {b['total']} (tensile {b['tensile']}, shear {b['shear']}) of {s['counts']['springs']}; "
          f"results in {sim.out_dir}")
    return 0
