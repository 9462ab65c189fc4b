"""Options shared by the scenario-driven subcommands."""

from __future__ import annotations


def add_scenario_args(p, optional: bool = False) -> None:
    if optional:
        p.add_argument("scenario", nargs="?", default=None, help="scenario TOML file")
    else:
        p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override a scenario value (TOML syntax), may be repeated")
    p.add_argument("--device", choices=None, default=None, help="Warp device: cpu, cuda, cuda:N (default: scenario)")


def add_force_arg(p) -> None:
    p.add_argument("--force", action="store_true",
                   help="go on even when the estimated mesh, material-point or grid size is above the limit "
                        "(docs/scenario.md, 'What is checked before a run')")


def load(args):
    from .._warp import DEVICE_PATTERN
    from ..scenario import ScenarioError, load_scenario

    sc = load_scenario(args.scenario, args.overrides)
    if args.device is not None:
        if not DEVICE_PATTERN.match(args.device):
            raise ScenarioError(f"--device {args.device!r}: expected cpu, cuda or cuda:N with N >= 0")
        sc.simulation.device = args.device
    return sc


def resolve_device(sc, args) -> str:
    """The Warp device of the scenario (or --device); a ScenarioError when it does not exist on this machine."""
    from .._warp import resolve_device as _resolve
    from ..scenario import ScenarioError

    try:
        return _resolve(sc.simulation.device)
    except ValueError as e:
        where = "--device" if getattr(args, "device", None) is not None else "simulation.device"
        raise ScenarioError(f"{where}: {e}") from None


def check_output_dir(path, where: str) -> None:
    """Refuse an output directory that is, or lies below, an existing file (before anything is written)."""
    from pathlib import Path

    from ..scenario import ScenarioError

    p = Path(path)
    for q in (p, *p.parents):
        if q.exists() and not q.is_dir():
            what = "is an existing file" if q == p else f"lies below the existing file {q}"
            raise ScenarioError(f"{where} {str(path)!r}: {what}; give a directory")
