"""The paper's three experiments on the bench, and three beyond it (``arcosim reproduce``).

1. actuator self-identification with the load detached (mode 0);
2. five rigid maneuvers with different noise seeds (mode 1), with the actuator terms
   of experiment 1 → Table II next to the paper's own rows, and Fig. 4;
3. a flexible maneuver with energy at all three modes (mode 2), with the mean k̂, B̂
   of experiment 2 → Fig. 5 (the flexible response) and Fig. 6 (estimated against
   true angle of every mass, the model-based observer of experiment 4 beside it);
4. beyond the paper: the whole bench chain (every J_i, k_i, B_i, and n) identified
   from one identification record with only the actuator terms of experiment 1
   known (:mod:`arcosim.identification.whole_chain`), then every mass's angle
   estimated in mode 2 (model-based observer) with those parameters alone → Fig. 7;
5. beyond the paper: a load torque on mass 3 (a step of a tenth of the drive's peak
   torque, then a 2 rad/s sine) during the broadband maneuver, estimated from the motor
   alone (model-based observer with ``load_mass = 3``), with the true chain and with
   experiment 4's chain: settling time, settled error, lag of the sine (scenario
   ``load-torque``, :mod:`arcosim.identification.load_torque`) → Fig. 8.

Writes ``report.md``, the CSV of every run and the PNG figures into ``--out``
(default ``reports/``), and prints the tables. Refuses to start when one of those
files exists there, unless ``--force`` (``make demo`` passes it). Realistic sensors (2000-count
encoder, 5 mA current noise) unless ``--ideal``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from arcosim.cli.options import add_fmus_option
from arcosim.experiments.report import text_table
from arcosim.experiments.reproduce import (
    LOAD_HEADER,
    TABLE_II_HEADER,
    WHOLE_CHAIN_HEADER,
    actuator_rows,
    load_angle_rows,
    load_rows,
    reproduce,
    state_rows,
    table_ii_rows,
    whole_chain_rows,
    whole_state_rows,
)


def add_parser(
    subparsers: argparse._SubParsersAction,
) -> None:
    """Register ``arcosim reproduce``."""
    p = subparsers.add_parser(
        "reproduce",
        help="run the paper's three experiments and three more, write the report",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--out", type=Path, default=Path("reports"), help="output folder (default reports/)"
    )
    p.add_argument("--ideal", action="store_true", help="ideal sensors")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--force", action="store_true", help="replace the report's files if they exist")
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
    )
    print("\n1. Actuator self-identification (load detached)")
    print(text_table(["term", "identified", "true", "error"], actuator_rows(results)))
    print("\n2. Table II: five rigid maneuvers (ours) next to the paper's")
    print(text_table(TABLE_II_HEADER, table_ii_rows(results)))
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
