"""Options shared by the scenario-driven subcommands."""

from __future__ import annotations


def add_scenario_args(p) -> None:
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override a scenario value (TOML syntax), may be repeated")
    p.add_argument("--device", choices=None, default=None, help="Warp device: cpu, cuda, cuda:N (default: scenario)")


def load(args):
    from ..scenario import ScenarioError, load_scenario

    sc = load_scenario(args.scenario, args.overrides)
    if args.device is not None:
        if not (args.device == "cpu" or args.device.startswith("cuda")):
            raise ScenarioError(f"--device {args.device!r}: expected cpu, cuda or cuda:N")
        sc.simulation.device = args.device
    return sc
