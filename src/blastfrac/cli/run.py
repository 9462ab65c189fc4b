"""``blastfrac run SCENARIO``: run a scenario and write its results."""

from __future__ import annotations

import sys

from .common import add_force_arg, add_scenario_args, check_output_dir, load, resolve_device


def add_parser(sub) -> None:
    p = sub.add_parser("run", help="run a scenario", description="Run a scenario and write results to its output directory.")
    add_scenario_args(p, optional=True)
    p.add_argument("--out", default=None, help="output directory (default: output.directory of the scenario)")
    p.add_argument("--max-steps", type=int, default=None, help="stop after N steps of the dynamic stage")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--restart", default=None, metavar="DIR",
                   help="continue the run whose output directory is DIR from its checkpoint.npz (the scenario "
                        "defaults to DIR/resolved.toml; only simulation.end_time, max_steps, progress, device, threads and "
                        "[output] may differ). On a CPU the results are bit-identical to a run that went through.")
    add_force_arg(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..scenario import ScenarioError
    from ..scenario.sizes import check_sizes
    from pathlib import Path

    from ..simulation import CHECKPOINT_NAME, RunInterrupted, Simulation, SimulationError

    ckpt = None
    if args.restart is not None:
        d = Path(args.restart)
        ckpt = d / CHECKPOINT_NAME
        if not ckpt.is_file():
            raise ScenarioError(f"--restart {args.restart!r}: no {CHECKPOINT_NAME} there (output.checkpoint_interval "
                                "writes one, and so does Ctrl-C)")
        if args.scenario is None:
            args.scenario = str(d / "resolved.toml")
        if args.out and Path(args.out).resolve() != d.resolve():
            raise ScenarioError("--restart continues in its own directory; leave out --out")
        args.out = str(d)
    elif args.scenario is None:
        raise ScenarioError("give a scenario file (or --restart DIR)")
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
        s = sim.run(progress=False if args.no_progress else None, restart=ckpt)
    except SimulationError as e:
        print(f"error: {e}", file=sys.stderr)   # summary.json (status 'failed') and the CSVs are written
        return 1
    except RunInterrupted as e:
        print(f"{e} (t = {sim.time * 1e6:.2f} µs, step {sim.steps})", file=sys.stderr)
        return e.exit_code
    except ValueError as e:                     # a checkpoint of another scenario
        raise ScenarioError(str(e)) from None
    except OSError as e:                        # read-only or full output directory: one clear line, exit 2
        where = e.filename or sim.out_dir
        raise ScenarioError(f"cannot write the results in {sim.out_dir} ({e.strerror or e} at {where}); every file "
                            "is written whole or not at all, so what is there is complete; free space or give "
                            "another --out") from None
    b = s["broken_springs"]
    print(f"{s['steps']} steps, t = {s['simulated_time'] * 1e6:.2f} µs, wall {s['wall_time_s']:.1f} s; "
          f"broken springs {b['total']} (tensile {b['tensile']}, shear {b['shear']}"
          f"{', crushed %d' % b['crushed'] if b.get('crushed') else ''}) of {s['counts']['springs']}; "
          f"results in {sim.out_dir}")
    return 0
