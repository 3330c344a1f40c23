"""``arcosim sweep SPEC.toml [--scheduler ADDRESS] [--workers N] [--out DIR] [--resume]``:
Monte Carlo and grid sweeps of co-simulations on Dask (:mod:`arcosim.sweeps.runner`;
the spec's format: :mod:`arcosim.sweeps.spec`).

Without ``--scheduler`` a ``dask.distributed.LocalCluster`` of ``--workers`` processes
runs here; with it the same tasks go to that cluster. Rows are appended to
``results.csv`` as runs finish; ``--resume`` runs only the missing ones. While it
runs the sweep holds the folder's lock: a second sweep into it is refused, naming the
pid and start time of the first. Exits 1 when some runs failed, 3 when all did.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from arcosim import UserError, same_file
from arcosim.cli.options import add_command, add_fmus_option, whole_number
from arcosim.sweeps import RESULTS, SUMMARY, load_spec, read_results, sweep

#: Exit statuses of a sweep that ran: some runs failed, every run failed.
SOME_FAILED, ALL_FAILED = 1, 3


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim sweep``."""
    p = add_command(
        subparsers,
        "sweep",
        summary="run a parameter sweep on Dask",
        description="""
Run a Monte Carlo or grid sweep of co-simulations described by a TOML spec, on a
local Dask cluster of --workers processes or on the cluster at --scheduler. Rows are
appended to results.csv in --out as runs finish; --resume runs only the missing
ones. A second sweep into the same folder is refused while the first runs.

Exit status: 0 when every run succeeded, 1 when some runs failed, 3 when all
failed (the count on stderr, each run's error in results.csv), 2 for a refusal.""",
        examples="""
arcosim sweep examples/sweep_noise_encoder_gdist.toml --workers 2 --out sweeps/noise
arcosim sweep spec.toml --out sweeps/noise --resume""",
    )
    p.add_argument("spec", type=Path, help="the sweep specification (TOML)")
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="address of an existing Dask scheduler (default: a local cluster)",
    )
    p.add_argument(
        "--workers",
        type=whole_number(1, 1024),
        default=2,
        metavar="N",
        help="worker processes of the local cluster, 1 to 1024 (default 2)",
    )
    p.add_argument("--out", type=Path, metavar="DIR", help="output folder (default sweeps/<name>)")
    p.add_argument("--resume", action="store_true", help="finish an interrupted sweep in --out")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_fmus_option(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    spec = load_spec(args.spec)
    out = args.out or Path("sweeps") / spec.name
    for name in (RESULTS, SUMMARY):
        if same_file(args.spec, out / name):
            raise UserError(f"{args.spec}: the sweep writes {out / name}; keep the spec elsewhere")
    start = time.perf_counter()
    results = sweep(
        spec,
        out,
        args.scheduler,
        args.workers,
        args.resume,
        not args.no_progress,
        fmu_dir=args.fmus,
    )
    rows = read_results(results)
    failed = sum(1 for r in rows if r["error"])
    print(
        f"{len(rows)} runs ({failed} failed) in {time.perf_counter() - start:.1f} s; "
        f"wrote {results} and {out / SUMMARY}"
    )
    return _exit_status(failed, len(rows), results)


def _exit_status(failed: int, runs: int, results: Path) -> int:
    """0 when every run succeeded, :data:`SOME_FAILED` when some failed and
    :data:`ALL_FAILED` when all did, the count said on stderr."""
    if not failed:
        return 0
    count = f"all {runs} runs failed" if failed == runs else f"{failed} of {runs} runs failed"
    print(
        f"arcosim sweep: {count}; their errors are in {results} (column error) and summary.md",
        file=sys.stderr,
    )
    return ALL_FAILED if failed == runs else SOME_FAILED
