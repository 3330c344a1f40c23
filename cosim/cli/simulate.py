"""``arcosim simulate``: run one scenario with any parameter overridden.

    arcosim simulate [--scenario NAME] [--masses N] [--set plant.k[2]=0.2]
                     [--set observer.g_dist=200] [--ideal] [--ordering jacobi]
                     [--step H] [--duration S] [--out FILE.csv] [--json]

The CSV holds ``time``, the measured ``i_a``, ``omega_m``, ``theta_m`` (so it is a
log that ``arcosim identify`` accepts) and every recorded signal as
``plant.<name>`` / ``observer.<name>``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

from arcosim.build.builder import fmu_variables
from arcosim.build.recipes import check_masses
from arcosim.cli.options import add_fmus_option, fmu_folder
from arcosim.errors import UserError
from arcosim.experiments.scenarios import SCENARIOS, recording_columns, run_scenario
from arcosim.fmu.flexchain.defaults import STEP
from arcosim.host.master import ORDERINGS
from arcosim.host.overrides import split_overrides
from arcosim.logs import write_csv


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim simulate``."""
    p = subparsers.add_parser(
        "simulate",
        help="run one scenario (plant + observer)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    names = ", ".join(f"{s.name} ({s.description})" for s in SCENARIOS.values())
    p.add_argument("--scenario", default="flexible", help=f"one of: {names}")
    p.add_argument("--masses", type=int, default=3, help="number of load masses (default 3)")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="FMU.NAME=VALUE",
        help="parameter of plant or observer, repeatable",
    )
    p.add_argument(
        "--ideal", action="store_true", help="ideal sensors: exact angle, true velocity, no noise"
    )
    p.add_argument("--ordering", choices=ORDERINGS, default="gauss-seidel")
    p.add_argument(
        "--step", type=float, default=STEP, help=f"communication step in s (default {STEP:g})"
    )
    p.add_argument("--duration", type=float, help="length in s (default: the scenario's)")
    p.add_argument("--out", type=Path, help="CSV of every recorded signal (a log for identify)")
    p.add_argument("--json", action="store_true", help="print the final observer outputs as JSON")
    add_fmus_option(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    if args.scenario not in SCENARIOS:
        raise UserError(f"--scenario {args.scenario!r}: use one of {', '.join(SCENARIOS)}")
    if not args.step > 0:
        raise UserError(f"--step {args.step}: the step must be > 0 s")
    scenario = SCENARIOS[args.scenario]
    if args.duration is not None:
        if not args.duration > 0:
            raise UserError(f"--duration {args.duration}: the duration must be > 0 s")
        scenario = dataclasses.replace(scenario, duration=args.duration)
    n = check_masses(args.masses)
    folder = fmu_folder(args, n)
    variables = fmu_variables(folder)
    overrides = split_overrides(args.set, variables)
    recording = run_scenario(
        scenario,
        n,
        overrides["plant"],
        overrides["observer"],
        h=args.step,
        ordering=args.ordering,
        ideal=args.ideal,
        fmu_dir=folder,
    )
    if args.out:
        write_csv(args.out, recording_columns(recording))
    final = {
        key.split(".", 1)[1]: float(series[-1])
        for key, series in recording.signals.items()
        if key.startswith("observer.")
    }
    if args.json:
        print(json.dumps(final, indent=2))
    else:
        print(
            f"{scenario.name}: {len(recording.time) - 1} steps of {args.step} s ({args.ordering})"
        )
        for key, value in final.items():
            if value:
                print(f"  observer.{key:22s} {value:.6g}")
        if args.out:
            print(f"wrote {args.out}")
    return 0
