"""``blastfrac run SCENARIO``: run a scenario and write its results."""

from __future__ import annotations

import sys

from .common import add_scenario_args, load


def add_parser(sub) -> None:
    p = sub.add_parser("run", help="run a scenario", description="Run a scenario and write results to its output directory.")
    add_scenario_args(p)
    p.add_argument("--out", default=None, help="output directory (default: output.directory of the scenario)")
    p.add_argument("--max-steps", type=int, default=None, help="stop after N steps of the dynamic stage")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..scenario import ScenarioError
    from ..simulation import Simulation, SimulationError

    sc = load(args)
    if args.out:
        sc.output.directory = args.out
    if args.max_steps is not None and args.max_steps <= 0:
        raise ScenarioError("--max-steps must be a positive integer")
    try:
        sim = Simulation(sc, max_steps=args.max_steps)
    except ValueError as e:
        raise ScenarioError(str(e)) from None
    try:
        s = sim.run(progress=False if args.no_progress else None)
    except SimulationError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    b = s["broken_springs"]
    print(f"{s['steps']} steps, t = {s['simulated_time'] * 1e6:.2f} µs, wall {s['wall_time_s']:.1f} s; "
          f"broken springs {b['total']} (tensile {b['tensile']}, shear {b['shear']}) of {s['counts']['springs']}; "
          f"results in {sim.out_dir}")
    return 0
