"""``blastfrac explosive NAME | --file F``: print a JWL set and its CJ consistency check."""

from __future__ import annotations

import argparse
import sys
import tomllib

from pydantic import ValidationError

_KEYS = ("rho0", "D", "A", "B", "R1", "R2", "omega", "E0")


def add_parser(subparsers) -> None:
    """Register the ``explosive`` subcommand on an argparse ``subparsers`` object."""
    p = subparsers.add_parser(
        "explosive",
        help="print a JWL set, p(V=1,E0) and its CJ state from the JWL Hugoniot",
        description="Print a JWL set, the pressure at V=1 with E0 and the CJ state (D_CJ, P_CJ, V_CJ) "
        "computed from the set's own Hugoniot; warn when D_CJ differs from the given D by more than 5 %.",
    )
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("name", nargs="?", help="library explosive (emulsion, petn, tnt, anfo)")
    g.add_argument("--file", metavar="F", help="TOML file with rho0, D, A, B, R1, R2, omega, E0 (SI), top level or [explosive.constants]")
    p.set_defaults(func=run)


def _load_file(path: str):
    from blastfrac.materials.jwl import JWLParams
    from blastfrac.scenario.explosive import JWLConstants

    with open(path, "rb") as fh:
        data = tomllib.load(fh)
    if isinstance(data.get("explosive"), dict):
        data = data["explosive"]
    if isinstance(data.get("constants"), dict):
        data = data["constants"]
    return JWLParams(**JWLConstants(**data).model_dump())


def run(args) -> int:
    """Print the report; 0 on success, 2 on a user error (message on stderr)."""
    from blastfrac.explosives.library import cj_report, get_explosive

    try:
        if getattr(args, "file", None):
            params, label = _load_file(args.file), args.file
        else:
            params, label = get_explosive(args.name), args.name
    except KeyError as exc:
        print(f"blastfrac explosive: {exc.args[0]}", file=sys.stderr)
        return 2
    except (OSError, tomllib.TOMLDecodeError) as exc:
        print(f"blastfrac explosive: cannot read '{args.file}': {exc}", file=sys.stderr)
        return 2
    except ValidationError as exc:
        errs = "; ".join(f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in exc.errors())
        print(f"blastfrac explosive: invalid constants in '{args.file}': {errs}", file=sys.stderr)
        return 2
    r = cj_report(params, label)
    lines = [
        f"Explosive: {label}",
        f"  rho0  = {r['rho0']:.1f} kg/m^3",
        f"  D     = {r['D']:.0f} m/s (given)",
        f"  A     = {r['A'] / 1e9:.4g} GPa    B  = {r['B'] / 1e9:.4g} GPa",
        f"  R1    = {r['R1']:.4g}    R2 = {r['R2']:.4g}    omega = {r['omega']:.4g}",
        f"  E0    = {r['E0'] / 1e9:.4g} GJ/m^3",
        f"  p(V=1, E0) = {r['p_V1_E0'] / 1e9:.4g} GPa",
        "CJ state from the JWL Hugoniot:",
        f"  D_CJ = {r['D_cj']:.1f} m/s    P_CJ = {r['p_cj'] / 1e9:.4g} GPa    V_CJ = {r['V_cj']:.4f}    u_CJ = {r['u_cj']:.1f} m/s",
        f"  rho0 D^2/4 (gamma=3 estimate with the given D) = {r['rho0'] * r['D'] ** 2 / 4 / 1e9:.4g} GPa",
    ]
    print("\n".join(lines))
    if r["warn"]:
        print(f"WARNING: {r['message']}")
    else:
        print(r["message"])
    return 0


def main(argv: list[str] | None = None) -> int:
    """Stand-alone entry for testing: ``python -m blastfrac.cli.explosive NAME``."""
    parser = argparse.ArgumentParser(prog="blastfrac")
    add_parser(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["explosive", *(sys.argv[1:] if argv is None else argv)])
    return run(args)


if __name__ == "__main__":
    raise SystemExit(main())
