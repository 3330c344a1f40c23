"""``arcosim reproduce [--out DIR] [--ideal] [--all-csv] [--fmus DIR] [--force]``: the paper's
experiments and four beyond them (:mod:`arcosim.experiments.reproduce`).

Writes ``report.md``, the runs as CSV (one per maneuver, its log; ``--all-csv``: every
run, every signal) and the PNG figures into ``--out`` (default ``reports/``), and prints
the tables. Refuses to start when one of those files exists there, unless ``--force``
(``make demo`` passes it); with it, the report's files this run does not write (an
earlier ``--all-csv`` run's) are kept and named in a warning. Realistic sensors
(2000-count encoder, 5 mA current noise) unless ``--ideal``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from arcosim import reproduce
from arcosim.cli.options import add_command, add_fmus_option, tool_names_option


def add_parser(
    subparsers: argparse._SubParsersAction,
) -> None:
    """Register ``arcosim reproduce``."""
    p = add_command(
        subparsers,
        "reproduce",
        summary="run the paper's three experiments and four beyond them, write the report",
        description="""
Run the paper's three experiments (the actuator's self-identification, Table II's
rigid maneuvers, the state estimation by the recursion) and four beyond them (the
whole chain from the motor alone, the load torque, a flexible link from the hub alone,
motion control from the motor alone), print their tables and write report.md, the
figures (PNG) and the runs as CSV into --out. By default one run per maneuver (selfid,
rigid_seed1, flexible, identification, load_true_chain, flexible_link), each its
log only (time, i_a, omega_m, theta_m: what arcosim identify reads; about 7 MB in
all); --all-csv writes every run with every recorded signal (about 100 MB). Refuses a
folder that already holds the report's files unless --force (then an earlier
--all-csv run's files it does not rewrite are kept, and named). Realistic sensors
(2000-count encoder, 5 mA current noise) unless --ideal. Takes a minute or two.""",
        examples="""
arcosim reproduce --out reports
arcosim reproduce --out reports --ideal --all-csv --force""",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=Path("reports"),
        metavar="DIR",
        help="output folder (default reports/)",
    )
    p.add_argument("--ideal", action="store_true", help="ideal sensors")
    p.add_argument(
        "--all-csv",
        action="store_true",
        help="write every run with every recorded signal as CSV (about 100 MB; default: "
        "one run per maneuver, its log only, about 6 MB)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar, no status lines")
    p.add_argument("--force", action="store_true", help="replace the report's files if they exist")
    tool_names_option(p)
    add_fmus_option(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    start = time.perf_counter()
    results = reproduce(
        args.out,
        args.ideal,
        show_progress=not args.no_progress,
        fmu_dir=args.fmus,
        force=args.force,
        all_csv=args.all_csv,
        tool_names=args.tool_names,
    )
    print(results.text())
    print(
        f"\nwrote {args.out / 'report.md'} and {len(results.files) - 1} more files "
        f"in {time.perf_counter() - start:.0f} s"
    )
    return 0
