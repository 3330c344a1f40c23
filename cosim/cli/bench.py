"""``arcosim bench NAME [ARGS...]``: run a benchmark (accuracy, speed, control, public,
thirdparty) of a source checkout.

The benchmarks live in the repository's ``benchmarks/`` folder (they are not part of
the installed package); this command finds that folder from the current directory
upwards and runs ``benchmarks/<name>.py`` with ``ARGS`` (``--help`` lists them).
"""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

from arcosim import UserError
from arcosim.cli.options import add_command

#: Benchmark name → module of the ``benchmarks`` package.
BENCHMARKS = {
    "accuracy": "accuracy",
    "speed": "speed",
    "control": "control_accuracy",
    "fleet": "fleet_accuracy",
    "public": "public_records",
    "thirdparty": "thirdparty_chain",
    "tracking": "tracking_accuracy",
    "verdict": "verdict_accuracy",
}


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim bench``."""
    p = add_command(
        subparsers,
        "bench",
        summary="run a benchmark of the source checkout (accuracy, speed, control, public, …)",
        description="""
Run one of the benchmarks in a source checkout's benchmarks/ folder (they are not
part of the installed package): the folder is found from the current directory
upwards, and ARGS go to the benchmark (arcosim bench NAME --help lists them).""",
        examples="""
arcosim bench accuracy
arcosim bench speed --help
arcosim bench public --data DIR     # public measured records, see its --help
arcosim bench thirdparty --fmus DIR # a chain of Dymola-exported FMUs, see its --help""",
    )
    p.add_argument("name", choices=sorted(BENCHMARKS), help="which benchmark")
    p.add_argument("args", nargs=argparse.REMAINDER, help="the benchmark's own arguments")
    p.set_defaults(execute=_execute)


def checkout_root(start: Path) -> Path:
    """The source checkout holding ``start``: the nearest folder upwards with
    ``pyproject.toml`` and ``benchmarks/__init__.py``."""
    for folder in (start, *start.parents):
        if (folder / "pyproject.toml").is_file() and (folder / "benchmarks/__init__.py").is_file():
            return folder
    raise UserError(
        f"no arcosim source checkout at or above {start}: the benchmarks are part of the "
        "repository, not of the installed package; run `arcosim bench` inside a clone"
    )


def _execute(args: argparse.Namespace) -> int:
    root = checkout_root(Path.cwd().resolve())
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    package = importlib.import_module("benchmarks")
    module = importlib.import_module(f"benchmarks.{BENCHMARKS[args.name]}")
    return package.main(args.name, module.add_parser, args.args)
