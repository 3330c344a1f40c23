"""Options several commands share, and the checks every CLI input gets where it enters.

Every subcommand's parser is made by :func:`add_command`: a description and examples
written for a terminal (the contract in detail is docs/cli.md). Numbers are parsed by
:func:`number` / :func:`whole_number` (argparse ``type=``): a value that is not a finite
number in its range is refused with one line naming the option and the range.
:func:`check_steps` refuses a step and a length that give no sample or more than
:data:`MAX_STEPS`. Outputs are checked by :mod:`arcosim.outputs` before any work starts.
"""

from __future__ import annotations

import argparse
import math
import textwrap
from collections.abc import Callable
from pathlib import Path

from arcosim import UserError, ensure_built
from arcosim.fmu.flexchain import STEP
from arcosim.host import MAX_STEPS, MAX_TIME, MIN_STEP


def add_command(
    subparsers: argparse._SubParsersAction,
    name: str,
    *,
    summary: str,
    description: str,
    examples: str,
) -> argparse.ArgumentParser:
    """A subcommand's parser whose ``--help`` reads in a terminal.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The ``arcosim`` parser's subcommands.
    name : str
        The subcommand, e.g. ``"identify"``.
    summary : str
        One line for ``arcosim --help``'s list of commands.
    description : str
        Plain text, no markup: what the command does and what to give first.
    examples : str
        Command lines, one a line (a long one continued with `` \\`` on lines indented
        further); shown indented under ``examples:`` at the end of the help.

    Returns
    -------
    argparse.ArgumentParser
        The subcommand's parser, to add its options to.
    """
    lines = textwrap.dedent(examples).strip("\n").splitlines()
    epilog = "examples:\n" + "\n".join(f"  {line}" if line.strip() else "" for line in lines)
    epilog += (
        "\n\nEvery option, output and exit status: the documentation's page\n"
        f'"The command line", section "arcosim {name}".'
    )
    return subparsers.add_parser(
        name,
        help=summary,
        description=description.strip(),
        epilog=epilog,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def number(
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    unit: str = "",
) -> Callable[[str], float]:
    """An argparse ``type``: a finite float within [low, high] (``low_open``: > low).

    Examples
    --------
    >>> number(0.0, 10.0, low_open=True, unit="s")("2.5")
    2.5
    """

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        below = low is not None and (value <= low if low_open else value < low)
        above = high is not None and value > high
        if not math.isfinite(value) or below or above:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not {describe_range(low, high, low_open, unit)}"
            )
        return value

    return parse


def whole_number(low: int, high: int) -> Callable[[str], int]:
    """An argparse ``type``: an integer from ``low`` to ``high``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number from {low} to {high}")
        return value

    return parse


def describe_range(
    low: float | None, high: float | None, low_open: bool = False, unit: str = ""
) -> str:
    """``"a finite number > 0 and <= 86400 s"``: the words of a range, for messages."""
    parts = []
    if low is not None:
        parts.append(f"{'>' if low_open else '>='} {low:g}")
    if high is not None:
        parts.append(f"<= {high:g}")
    text = "a finite number" + (" " + " and ".join(parts) if parts else "")
    return text + (f" {unit}" if unit else "")


def step_option(parser: argparse.ArgumentParser, default: float = STEP) -> None:
    """``--step H``: a communication step in s."""
    parser.add_argument(
        "--step",
        type=number(MIN_STEP, MAX_TIME, unit="s"),
        default=default,
        metavar="H",
        help=f"communication step in s, {MIN_STEP:g} to {MAX_TIME:g} (default {default:g})",
    )


def check_steps(option: str, length: float, step: float, length_option: str = "--duration") -> int:
    """The number of steps of ``step`` s in ``length`` s; refuse none or too many.

    Raises
    ------
    UserError
        When ``length / step`` rounds to 0 or exceeds :data:`MAX_STEPS`.

    Examples
    --------
    >>> check_steps("--step", 10.0, 1e-3)
    10000
    """
    steps = round(length / step)
    if steps < 1:
        raise UserError(
            f"{option} {step:g}: longer than the run ({length_option} {length:g} s), so not "
            f"one step; use a step <= {length:g} s"
        )
    if steps > MAX_STEPS:
        raise UserError(
            f"{option} {step:g}: {steps:.3g} steps in {length:g} s, more than {MAX_STEPS:,}; "
            f"use a step >= {length / MAX_STEPS:.3g} s or a shorter run"
        )
    return steps


def log_options(parser: argparse.ArgumentParser, set_help: str) -> None:
    """A drive log and what is known of the drive: ``LOG``, ``--set NAME=VALUE`` (the
    observer's parameters, as ``set_help`` says), ``--scale COLUMN=FACTOR``."""
    parser.add_argument("log", type=Path, help="CSV log with time, i_a, omega_m, theta_m")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    parser.add_argument(
        "--scale",
        action="append",
        default=[],
        metavar="COLUMN=FACTOR",
        help="multiply a log column to get SI units (i_a=0.001 for mA), repeatable",
    )


def force_option(parser: argparse.ArgumentParser) -> None:
    """The options of a command that writes a file: ``--force`` (replace an existing
    output file) and ``--tool-names`` (:func:`tool_names_option`)."""
    parser.add_argument("--force", action="store_true", help="replace the output file if it exists")
    tool_names_option(parser)


def tool_names_option(parser: argparse.ArgumentParser) -> None:
    """``--tool-names``: write CSV columns and JSON keys as names other tools keep
    (``theta_hat_1`` for ``theta_hat[1]``, :func:`arcosim.logs.tool_name`)."""
    parser.add_argument(
        "--tool-names",
        action="store_true",
        help="name CSV columns and JSON keys for MATLAB/R/spreadsheets: theta_hat_1, not "
        "theta_hat[1] (units are always in FILE.units.json beside each CSV)",
    )


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
    if args.fmus is not None and args.fmus.exists() and not args.fmus.is_dir():
        raise UserError(f"--fmus {args.fmus}: is a file; name the folder of the FMUs")
    return ensure_built(n, args.fmus)


def fmu_inputs(folder: Path) -> list[Path]:
    """The files of a folder of FMUs a command reads (no output may be one of them)."""
    return sorted(p for p in folder.glob("*") if p.suffix in (".fmu", ".ssp"))
