"""``arcosim build [--masses N] [--elements E] [--out DIR]``: build the project's FMUs and
their SSP.

Writes ``MotorChainPlant.fmu``, ``ReactionTorqueObserver.fmu``,
``ExcitationSource.fmu``, ``ActionReaction.ssp`` and the flexible-link plant
``FlexLinkPlant.fmu`` into ``--out`` (default: the per-user cache,
:mod:`arcosim.build.cache`), for n load masses (model identifiers ``MotorChainPlant_n3``
…) and a link of E Hermite elements (``FlexLinkPlant_e6`` …).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from arcosim import build_all
from arcosim.build import (
    MAX_ELEMENTS,
    MAX_MASSES,
    MIN_ELEMENTS,
    MIN_MASSES,
    check_elements,
    check_masses,
)
from arcosim.cli.options import add_command
from arcosim.fmu.flexchain import LINK_ELEMENTS


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim build``."""
    p = add_command(
        subparsers,
        "build",
        summary="build the FMUs",
        description="""
Build the plant, observer and excitation FMUs and their SSP system for n load
masses, and the flexible-link plant for E Hermite elements, into a folder (default:
the per-user cache, where every other command looks for them; they are built there on
first use anyway, so this is only needed to get the files themselves).""",
        examples="""
arcosim build --out fmus
arcosim build --masses 2 --out fmus2
arcosim build --elements 8 --out fmus
arcosim build --out fmus --force    # replace a MotorChainPlant.fmu of your own there""",
    )
    p.add_argument(
        "--masses",
        type=int,
        default=3,
        metavar="N",
        help=f"number of load masses n, {MIN_MASSES} to {MAX_MASSES} (default 3)",
    )
    p.add_argument(
        "--elements",
        type=int,
        default=LINK_ELEMENTS,
        metavar="E",
        help=f"Hermite elements of the flexible link, {MIN_ELEMENTS} to {MAX_ELEMENTS} "
        f"(default {LINK_ELEMENTS})",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="DIR",
        help="output folder (default: the per-user cache, ~/.cache/arcosim/fmus/...)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="replace files of the names it writes that an earlier build did not write "
        "(its own FMUs and SSPs it replaces anyway)",
    )
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    elements = check_elements(args.elements)
    for path in build_all(check_masses(args.masses), args.out, elements, force=args.force):
        print(f"built {path}")
    return 0
