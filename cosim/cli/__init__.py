"""``cosim/cli/`` installed as ``arcosim.cli``: the ``arcosim`` command line, one
subcommand per module (``identify`` in several), dispatched through
``set_defaults(execute=…)``; nothing but ``arcosim.__main__`` imports it.

Modules, in the order a command runs (then the subcommands, in ``arcosim --help``'s order):

options                -- options several commands share, and the checks of every input
parameters             -- the observer's parameters ``identify`` and ``check`` know (``--set``)
build                  -- ``arcosim build``: the FMUs and their SSP into a folder
simulate               -- ``arcosim simulate``: one scenario, any parameter overridden
excite                 -- ``arcosim excite``: the excitation to play for identification
check                  -- ``arcosim check``: can a log support identification?
identify/              -- ``arcosim identify``: one module per method (its package lists them)
control                -- ``arcosim control``: the motion controller for a chain, its margins
example                -- ``arcosim example``: the sample log and its script into a folder
reproduce              -- ``arcosim reproduce``: the paper's experiments and the report
sweep                  -- ``arcosim sweep``: Monte Carlo and grid sweeps on Dask
fleet                  -- ``arcosim fleet``: many axes identified on Dask, their drift
ssp                    -- ``arcosim ssp``: an SSP system run
validate               -- ``arcosim validate``: FMUs checked as a strict host would
bench                  -- ``arcosim bench``: a benchmark of a source checkout

Whatever goes wrong, a user sees one line on stderr, never a Python traceback:

* a bad argument, file or value (:class:`~arcosim.errors.ArcosimError`, or an
  argument argparse refuses): ``arcosim: error: …`` and exit status 2;
* a record that cannot support the fit asked of it
  (:class:`~arcosim.identification.errors.RefusedFitError`, the log ``arcosim check`` says is
  not ok): ``arcosim: error: …`` and exit status 1;
* Python warnings (numpy's, a build's) are collected and printed after a command
  that succeeds, each once, as ``arcosim: warning: …``; a refusal prints only its line;
* Ctrl-C: ``arcosim: interrupted`` and exit status 130;
* anything else (a bug): ``arcosim: internal error: …`` naming the file the
  traceback was written to (in the temporary folder), and exit status 70
  (``EX_SOFTWARE``).
"""

from __future__ import annotations

import argparse
import datetime
import os
import sys
import tempfile
import traceback
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from arcosim import ArcosimError, RefusedFitError, __version__
from arcosim.cli import (
    bench,
    build,
    check,
    control,
    example,
    excite,
    fleet,
    reproduce,
    simulate,
    ssp,
    sweep,
    validate,
)
from arcosim.cli.identify import command as identify

#: Exit status of a refused input, and of an internal error (sysexits' EX_SOFTWARE).
EXIT_REFUSED, EXIT_USAGE, EXIT_INTERNAL, EXIT_INTERRUPTED = 1, 2, 70, 130
#: Exit status when the output's reader went away, as a tool killed by SIGPIPE.
EXIT_BROKEN_PIPE = 141


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose refusals are one line: ``arcosim: error: …``."""

    def error(self, message: str) -> NoReturn:
        print(f"arcosim: error: {message} (see `{self.prog} --help`)", file=sys.stderr)
        sys.exit(EXIT_USAGE)


def make_parser() -> argparse.ArgumentParser:
    """The full ``arcosim`` parser."""
    parser = OneLineParser(
        prog="arcosim",
        description="Sensorless identification and state estimation of flexible drives "
        "with FMI co-simulation (action-reaction method).",
    )
    parser.add_argument("--version", action="version", version=f"arcosim {__version__}")
    subparsers = parser.add_subparsers(
        title="commands", metavar="COMMAND", parser_class=OneLineParser
    )
    for module in (
        build,
        simulate,
        excite,
        check,
        identify,
        control,
        example,
        reproduce,
        sweep,
        fleet,
        ssp,
        validate,
        bench,
    ):
        module.add_parser(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``arcosim`` with ``argv`` (default: the process arguments); return the exit code."""
    parser = make_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as stop:  # a refused argument (one line printed), --help, --version
        return stop.code if isinstance(stop.code, int) else EXIT_USAGE
    if not hasattr(args, "execute"):
        parser.print_help()
        return EXIT_USAGE
    caught: list[str] = []
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            warnings.showwarning = lambda message, *_, **__: caught.append(one_line(str(message)))
            code = int(args.execute(args) or 0)
        for text in dict.fromkeys(caught):  # each once, after the command's own output
            print(f"arcosim: warning: {text}", file=sys.stderr)
        return code
    except ArcosimError as error:
        print(f"arcosim: error: {one_line(str(error))}", file=sys.stderr)
        return EXIT_REFUSED if isinstance(error, RefusedFitError) else EXIT_USAGE
    except KeyboardInterrupt:
        print("arcosim: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # the reader went away (`arcosim … | head`): stop quietly
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except Exception as error:  # a bug: one line here, the traceback in a file
        report = write_crash_report(argv if argv is not None else sys.argv[1:])
        where = f"details in {report}" if report else "and the details could not be written"
        print(
            f"arcosim: internal error: {type(error).__name__}: {one_line(str(error))[:300]} "
            f"({where}; please report it)",
            file=sys.stderr,
        )
        return EXIT_INTERNAL


def one_line(text: str) -> str:
    r"""``text`` on one line: its lines joined by `` | `` (FMU logs come as several).

    A Python traceback inside (an FMU's log of an internal error) keeps only its
    last line, the exception.

    Examples
    --------
    >>> one_line("step refused:\nTraceback (most recent call last):\n  File x\nValueError: no")
    'step refused: | ValueError: no'
    """
    lines, in_traceback = [], False
    for line in text.splitlines():
        if line.strip().startswith("Traceback (most recent call last):"):
            in_traceback = True
            continue
        if in_traceback and line[:1].isspace():
            continue
        in_traceback = False
        if line.strip():
            lines.append(line.strip())
    return " | ".join(lines)


def write_crash_report(argv: Sequence[str]) -> Path | None:
    """Write the current exception's traceback, the command and versions to a new file
    in the temporary folder; return its path (None if it cannot be written)."""
    try:
        fd, name = tempfile.mkstemp(prefix="arcosim-error-", suffix=".txt")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(f"arcosim {__version__}, Python {sys.version.split()[0]}, {sys.platform}\n")
            f.write(f"time: {datetime.datetime.now().isoformat(timespec='seconds')}\n")
            f.write(f"command: arcosim {' '.join(argv)}\n")
            f.write(f"folder: {os.getcwd()}\n\n")
            f.write(traceback.format_exc())
        return Path(name)
    except OSError:
        return None


if __name__ == "__main__":
    sys.exit(main())
