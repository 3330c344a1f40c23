"""``arcosim validate [FMU ...]``: check FMUs the way a strict FMI host would
(:mod:`arcosim.host.validate`; default: the FMUs for 3 masses in the per-user cache).

Prints the problems and exits 1 if there are any. A file that is not an FMU at all
(text, empty, a zip without ``modelDescription.xml``, a truncated zip, an SSP) is
refused with one line and exit status 2 before any FMU is run.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from arcosim import UserError, ensure_built, validate
from arcosim.cli.options import add_command
from arcosim.host import not_an_fmu


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim validate``."""
    p = add_command(
        subparsers,
        "validate",
        summary="check built FMUs for FMI compliance and behaviour",
        description="""
Check FMUs the way a strict FMI host would (model description, instantiation,
stepping, state save and restore); default: the FMUs for 3 masses in the per-user
cache, built if needed. Prints the problems and exits 1 if there are any; a file
that is not an FMU is refused with exit status 2 before any FMU runs.""",
        examples="""
arcosim validate
arcosim validate fmus/*.fmu""",
    )
    p.add_argument(
        "fmus",
        nargs="*",
        type=Path,
        help="FMU files (default: the FMUs for 3 masses in the per-user cache, built if needed)",
    )
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    fmus = args.fmus or sorted(ensure_built(3).glob("*.fmu"))
    for fmu in fmus:  # every input checked before any is run
        why = not_an_fmu(fmu)
        if why is not None:
            raise UserError(f"{fmu}: {why}")
    failed = 0
    for fmu in fmus:
        problems, notes = validate(fmu)
        print(f"{fmu}: {'OK' if not problems else f'{len(problems)} problem(s)'}")
        for line in problems:
            print(f"  problem: {line}")
        for line in notes:
            print(f"  note: {line}")
        failed += bool(problems)
    return 1 if failed else 0
