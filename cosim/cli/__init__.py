"""The ``arcosim`` command line: one subcommand per module, dispatched through
``set_defaults(execute=…)``."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from arcosim.cli import bench, build, identify, reproduce, simulate, ssp, sweep, validate
from arcosim.errors import ArcosimError
from arcosim.version import __version__


def make_parser() -> argparse.ArgumentParser:
    """The full ``arcosim`` parser."""
    parser = argparse.ArgumentParser(
        prog="arcosim",
        description="Sensorless identification and state estimation of flexible drives "
        "with FMI co-simulation (action-reaction method).",
    )
    parser.add_argument("--version", action="version", version=f"arcosim {__version__}")
    subparsers = parser.add_subparsers(title="commands", metavar="COMMAND")
    for module in (build, simulate, identify, reproduce, sweep, ssp, validate, bench):
        module.add_parser(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``arcosim`` with ``argv`` (default: the process arguments); return the exit code."""
    parser = make_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "execute"):
        parser.print_help()
        return 2
    try:
        return int(args.execute(args) or 0)
    except ArcosimError as error:
        print(f"arcosim: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
