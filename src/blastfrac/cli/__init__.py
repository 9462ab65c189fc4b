"""Command line: ``blastfrac run|check|bench|explosive|calibrate|sweep``.

User errors (bad scenario, missing file) print one message and exit with code 2, no traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

EXIT_USER_ERROR = 2

# subcommand modules, each exposing add_parser(subparsers) and run(args) -> int
_COMMANDS = ("run", "check", "bench", "explosive", "calibrate", "sweep")


def build_parser() -> argparse.ArgumentParser:
    from .. import __version__

    p = argparse.ArgumentParser(prog="blastfrac", description="Blast-induced rock fracture simulator (MPM + CDEM).")
    p.add_argument("--version", action="version", version=f"blastfrac {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    for name in _COMMANDS:
        try:
            mod = importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError:
            continue
        mod.add_parser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    from ..scenario.errors import ScenarioError

    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ScenarioError as e:
        print(f"error: {e}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
