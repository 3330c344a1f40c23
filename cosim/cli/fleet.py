"""``arcosim fleet identify FOLDER --out DIR`` and ``arcosim fleet drift DIR``: condition
monitoring of many axes (:mod:`arcosim.fleet`).

``identify`` identifies every log of the fleet's folder that the store in ``--out``
does not hold yet, on a local Dask cluster of ``--workers`` processes or the cluster at
``--scheduler``; ``drift`` compares each axis's latest trusted fit with its baseline,
exits 1 when any alarm is raised and with ``--plot PLOTDIR`` draws the drift
(:mod:`arcosim.fleet.figures`). Both only parse, call the library and print.
"""

from __future__ import annotations

import argparse
import datetime
import sys
from pathlib import Path

from arcosim import UserError, fleet_drift, fleet_figures, identify_fleet
from arcosim.cli.options import add_command, number, whole_number
from arcosim.fleet import THRESHOLD

#: Exit status of ``drift`` when any axis has an alarm.
ALARM = 1
#: Worker processes of the local cluster when ``--workers`` is not given.
WORKERS = 2


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim fleet`` and its two subcommands."""
    p = add_command(
        subparsers,
        "fleet",
        summary="identify many axes' logs on Dask; alarm on drift",
        description="""
Condition monitoring of a fleet of axes. `fleet identify` identifies every log of a
folder (one subfolder per axis with axis.toml and logs named by ISO date) that the
store in --out does not hold yet, one Dask task per log; `fleet drift` compares each
axis's latest trusted fit with its baseline and alarms on a change over the threshold
that the fits resolve (3 standard errors).""",
        examples="""
arcosim fleet identify fleet/ --out fleet-out --workers 2
arcosim fleet drift fleet-out
arcosim fleet drift fleet-out --json --threshold 0.1""",
    )
    commands = p.add_subparsers(title="fleet commands", metavar="COMMAND", required=True)
    for sub in (_add_identify(commands), _add_drift(commands)):
        sub.epilog = sub.epilog.replace(
            f'section "arcosim {sub.prog.split()[-1]}"', 'section "arcosim fleet"'
        )


def _add_identify(commands: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = add_command(
        commands,
        "identify",
        summary="identify every new log of the fleet into the store",
        description="""
Identify every log of FOLDER not yet in the store DIR/fleet.csv, each on a Dask
worker; a log that cannot be identified is recorded as failed with its reason and
the fleet goes on. Progress (done/total, failures, ETA) on stderr.

Exit status: 0 when every log of this run was identified, 1 when some failed, 2 for
a refusal (a wrong folder, axis.toml or log name, --out held by another run).""",
        examples="""
arcosim fleet identify fleet/ --out fleet-out
arcosim fleet identify fleet/ --out fleet-out --scheduler tcp://10.0.0.5:8786""",
    )
    p.add_argument("folder", type=Path, metavar="FOLDER", help="the fleet: one folder per axis")
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="the store's folder")
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="address of an existing Dask scheduler (default: a local cluster)",
    )
    where.add_argument(
        "--workers",
        type=whole_number(1, 1024),
        default=None,  # not 2: argparse would not see `--workers 2` given beside --scheduler
        metavar="N",
        help="worker processes of the local cluster, 1 to 1024 (default 2)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress lines on stderr")
    p.set_defaults(execute=_identify)
    return p


def _add_drift(commands: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = add_command(
        commands,
        "drift",
        summary="each axis's parameters against its baseline; alarms",
        description="""
Compare each axis's latest trusted identification in the store DIR with its baseline
(its first trusted one, or the first from --baseline). An alarm: a parameter changed
by more than --threshold (relative) and by more than 3 standard errors of the
difference, or a different number of masses. With --plot PLOTDIR: overview.png (every
axis's parameters, change from the baseline) and axis-<axis>.png per alarmed axis
(each parameter's history with its σ band and the threshold band).

Exit status: 0 when no alarm, 1 when any alarm, 2 for a refusal.""",
        examples="""
arcosim fleet drift fleet-out
arcosim fleet drift fleet-out --plot drift-figures --force
arcosim fleet drift fleet-out --json --threshold 0.1 --baseline 2026-01-01""",
    )
    p.add_argument(
        "out", type=Path, metavar="DIR", help="the store's folder (fleet identify --out)"
    )
    p.add_argument("--json", action="store_true", help="the report as JSON on stdout")
    p.add_argument(
        "--threshold",
        type=number(0.0, None, low_open=True),
        default=THRESHOLD,
        metavar="REL",
        help=f"relative change that alarms, > 0 (default {THRESHOLD}, i.e. 5 %%)",
    )
    p.add_argument(
        "--baseline",
        type=_iso_date,
        metavar="DATE",
        help="ISO date: each axis's baseline is its first trusted fit from then on",
    )
    p.add_argument(
        "--plot",
        type=Path,
        metavar="PLOTDIR",
        help="draw overview.png and axis-<axis>.png per alarmed axis into this folder",
    )
    p.add_argument(
        "--force", action="store_true", help="with --plot: replace figures of an earlier run"
    )
    p.set_defaults(execute=_drift)
    return p


def _iso_date(text: str) -> str:
    try:
        return datetime.date.fromisoformat(text).isoformat()
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an ISO date (2026-03-01)") from None


def _identify(args: argparse.Namespace) -> int:
    run = identify_fleet(
        args.folder,
        args.out,
        scheduler=args.scheduler,
        workers=WORKERS if args.workers is None else args.workers,
        progress=None if args.no_progress else sys.stderr,
    )
    if not run.identified:
        print(f"no new log: all {run.total} logs are in {run.store} already")
        return 0
    print(
        f"logs identified: {run.identified} ({run.failed} failed) in {run.seconds:.1f} s, "
        f"{run.skipped} already in the store; wrote {run.store}"
    )
    if run.failed:
        print(
            f"arcosim fleet identify: failed logs: {run.failed}; their reasons are in "
            f"{run.store} (column reason) and `arcosim fleet drift {args.out}`",
            file=sys.stderr,
        )
        return 1
    return 0


def _drift(args: argparse.Namespace) -> int:
    if args.force and args.plot is None:
        raise UserError("--force goes with --plot PLOTDIR (it replaces figures)")
    report = fleet_drift(args.out, threshold=args.threshold, baseline=args.baseline)
    figures = [] if args.plot is None else fleet_figures(report, args.plot, force=args.force)
    print(report.to_json() if args.json else report.text())
    for path in figures:  # beside JSON on stdout, on stderr
        print(f"wrote {path}", file=sys.stderr if args.json else sys.stdout)
    return ALARM if report.alarmed else 0
