"""``arcosim ssp FILE.ssp [--parameter-set NAME] [--stop S] [--step H] [--out FILE.csv]``:
run an SSP system (:func:`arcosim.host.ssp.run_ssp`) and write every output over time.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from arcosim import check_output, run_ssp, write_csv
from arcosim.cli.options import MAX_TIME, add_command, force_option, number, step_option


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim ssp``."""
    p = add_command(
        subparsers,
        "ssp",
        summary="run an SSP system (e.g. dist/ActionReaction.ssp)",
        description="""
Run an SSP system (a folder of FMUs and their connections, as arcosim build writes
ActionReaction.ssp) with one of its parameter sets, and write every output of every
component over time as CSV.""",
        examples="""
arcosim ssp fmus/ActionReaction.ssp --stop 2 --out run.csv
arcosim ssp fmus/ActionReaction.ssp --parameter-set bench --step 1e-4 --stop 1""",
    )
    p.add_argument("path", type=Path, help="the .ssp file")
    p.add_argument(
        "--parameter-set", default="bench", help="parameter set to apply (default bench)"
    )
    p.add_argument(
        "--stop",
        type=number(0.0, MAX_TIME, low_open=True, unit="s"),
        help=f"stop time in s, up to {MAX_TIME:g} (default: the SSP's DefaultExperiment)",
    )
    step_option(p)
    p.add_argument("--out", type=Path, help="CSV of every output of every component")
    force_option(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    if args.out:
        check_output(args.out, inputs=[args.path], force=args.force)
    recording = run_ssp(args.path, args.parameter_set, args.stop, args.step)
    if args.out:
        write_csv(
            args.out,
            {"time": recording.time, **recording.signals},
            units=recording.units,
            tool_names=args.tool_names,
            force=args.force,
        )
    print(f"{args.path}: {len(recording.time) - 1} steps of {args.step:g} s (Jacobi)")
    for key in ("observer.tau_reac_hat", "observer.theta_hat[1]", "plant.theta[1]"):
        if key in recording.signals:
            print(f"  final {key:24s} {recording[key][-1]:.6g}")
    if args.out:
        print(f"wrote {args.out}")
    return 0
