"""``arcosim example --out DIR``: the sample log and the script that identifies it,
copied out of the installed package (``arcosim/example-files/``, the same files as the
checkout's ``examples/``) so that quick start 2 runs without a checkout.
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

from arcosim import check_output_folder, refuse_existing, write_bytes
from arcosim.cli.options import add_command, force_option

#: The files written, by their path under ``--out`` (the script reads ``data/…``
#: beside itself).
FILES = ("identify_your_drive.py", "data/belt_drive.csv")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim example``."""
    p = add_command(
        subparsers,
        "example",
        summary="write the sample log and the script that identifies it into a folder",
        description="""
Write the sample drive log (data/belt_drive.csv: a belt drive with two load masses,
recorded in mA, encoder counts and counts/s, 20 s at 1 ms) and the script that
identifies it (identify_your_drive.py) into --out, to follow quick start 2 or to
start from with your own log. Existing files are replaced only with --force.""",
        examples="""
arcosim example --out first-hour
cd first-hour && python identify_your_drive.py""",
    )
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="folder to write into")
    force_option(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    """Refuse existing files (unless ``--force``), then copy every one of :data:`FILES`."""
    folder = check_output_folder(args.out)
    if not args.force:
        refuse_existing(folder, FILES)
    source = resources.files("arcosim") / "example-files"
    for name in FILES:
        target = folder / name
        target.parent.mkdir(parents=True, exist_ok=True)
        write_bytes(target, source.joinpath(*name.split("/")).read_bytes(), force=args.force)
        print(f"wrote {target}")
    return 0
