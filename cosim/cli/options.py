"""Options several commands share."""

from __future__ import annotations

import argparse
from pathlib import Path

from arcosim.build.builder import ensure_built


def add_fmus_option(parser: argparse.ArgumentParser) -> None:
    """``--fmus DIR``: the folder of FMUs a command runs."""
    parser.add_argument(
        "--fmus",
        type=Path,
        default=None,
        metavar="DIR",
        help="folder of the FMUs to run, built there if missing or built from other "
        "sources (default: the per-user cache)",
    )


def fmu_folder(args: argparse.Namespace, n: int) -> Path:
    """The folder of current FMUs for ``n`` masses that ``--fmus`` names (or the cache)."""
    return ensure_built(n, args.fmus)
