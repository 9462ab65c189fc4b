"""``blastfrac sweep SWEEP.toml``: run the cases of a sweep on Dask distributed (blastfrac.sweep)."""

from __future__ import annotations


def add_parser(sub) -> None:
    p = sub.add_parser("sweep", help="run a parameter sweep on Dask", description=(
        "Run the cases of a sweep file (a base scenario and its overrides) as separate processes on a Dask "
        "LocalCluster (one single-threaded worker per core) or on an existing scheduler; writes sweep.csv, "
        "sweep.json and sweep_comparison.png in the sweep's output directory (docs/sweeps.md)."))
    p.add_argument("sweep", help="sweep TOML file")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="address of a running Dask scheduler (tcp://host:8786); default: a local cluster")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: one per core)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..scenario import ScenarioError
    from ..sweep import load_sweep, run_sweep

    if args.workers is not None and args.workers <= 0:
        raise ScenarioError("--workers must be a positive integer")
    sw = load_sweep(args.sweep)
    rows = run_sweep(sw, scheduler=args.scheduler, workers=args.workers, progress=not args.no_progress)
    failed = [r for r in rows if r["status"] != "completed"]
    import json

    info = json.loads((sw.output / "sweep.json").read_text())["sweep"]
    sp = info["parallel_speedup"]
    print(f"{len(rows)} cases ({len(rows) - len(failed)} completed, {len(failed)} failed, "
          f"{len(info['skipped'])} skipped as done); sweep {info['sweep_wall_time_s']:.1f} s wall against "
          f"{info['sum_of_case_wall_times_s']:.1f} s summed over the cases run"
          + (f" ({sp:.2f}x)" if sp else "") + f"; results in {sw.output}")
    for r in failed:
        print(f"  case {r['case']} failed: {r['error']}")
    return 1 if failed else 0
