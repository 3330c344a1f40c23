"""``arcosim reproduce [--out DIR] [--ideal] [--fmus DIR] [--force]``: the paper's
experiments and two beyond them (:mod:`arcosim.experiments.reproduce`).

Writes ``report.md``, the CSV of every run and the PNG figures into ``--out``
(default ``reports/``), and prints the tables. Refuses to start when one of those
files exists there, unless ``--force`` (``make demo`` passes it). Realistic sensors (2000-count
encoder, 5 mA current noise) unless ``--ideal``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from arcosim.cli.options import add_fmus_option, tool_names_option
from arcosim.experiments import reproduce as experiments
from arcosim.experiments.findings import (
    LOAD_HEADER,
    TABLE_II_HEADER,
    TABLE_II_NOTE,
    WHOLE_CHAIN_HEADER,
    actuator_rows,
    load_angle_rows,
    load_rows,
    state_rows,
    table_ii_rows,
    whole_chain_rows,
    whole_state_rows,
)
from arcosim.experiments.report import text_table
from arcosim.experiments.reproduce import reproduce


def add_parser(
    subparsers: argparse._SubParsersAction,
) -> None:
    """Register ``arcosim reproduce``."""
    p = subparsers.add_parser(
        "reproduce",
        help="run the paper's three experiments and two beyond them, write the report",
        description=(__doc__ or "") + "\n" + (experiments.__doc__ or ""),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--out", type=Path, default=Path("reports"), help="output folder (default reports/)"
    )
    p.add_argument("--ideal", action="store_true", help="ideal sensors")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
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
        tool_names=args.tool_names,
    )
    print("\n1. Actuator self-identification (load detached)")
    print(text_table(["term", "identified", "true", "error"], actuator_rows(results)))
    print("\n2. Table II: five rigid maneuvers (ours) next to the paper's")
    print(text_table(TABLE_II_HEADER, table_ii_rows(results)))
    print(TABLE_II_NOTE)
    print("\n3. State estimation (recursion), score rms(θ̂_i − θ_i) / rms(θ_i − θ_m)")
    print(text_table(["mass", "recursion score", "naive θ_i = θ_m"], state_rows(results)))
    print(f"\n4. Whole chain from the motor alone (n = {results.masses} read from the record)")
    print(text_table(WHOLE_CHAIN_HEADER, whole_chain_rows(results)))
    print(text_table(["mass", "model-based score, identified chain"], whole_state_rows(results)))
    print("\n5. Load torque on mass 3 from the motor alone, % of the step")
    print(text_table(LOAD_HEADER, load_rows(results)))
    print(text_table(["observer", "mass 1", "mass 2", "mass 3"], load_angle_rows(results)))
    print(
        f"\nwrote {args.out / 'report.md'} and {len(results.files) - 1} more files "
        f"in {time.perf_counter() - start:.0f} s"
    )
    return 0
