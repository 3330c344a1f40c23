"""``arcosim build [--masses N] [--out DIR]``: build the project's FMUs and their SSP.

Writes ``MotorChainPlant.fmu``, ``ReactionTorqueObserver.fmu``,
``ExcitationSource.fmu`` and ``ActionReaction.ssp`` into ``--out`` (default: the
per-user cache, :mod:`arcosim.build.cache`), for n load masses (model identifiers
``MotorChainPlant_n3`` …).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from arcosim.build.builder import build_all
from arcosim.build.recipes import MAX_MASSES, MIN_MASSES, check_masses


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim build``."""
    p = subparsers.add_parser("build", help="build the FMUs", description=__doc__)
    p.add_argument(
        "--masses",
        type=int,
        default=3,
        help=f"number of load masses n, {MIN_MASSES} to {MAX_MASSES} (default 3)",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output folder (default: the per-user cache, ~/.cache/arcosim/fmus/...)",
    )
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    for path in build_all(check_masses(args.masses), args.out):
        print(f"built {path}")
    return 0
