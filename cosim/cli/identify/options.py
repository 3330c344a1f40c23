"""The options every method of ``arcosim identify`` shares, checked where they enter:
which options go with which method, ``--masses``, ``--chain`` (a whole-chain report
read back as ``--set`` assignments), ``--out`` (refused before any work) and the report
an offline fit writes.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path

from arcosim import (
    Chain,
    ChainFileError,
    UserError,
    check_output,
    read_chain,
    tool_keys,
    write_text,
)
from arcosim.build import check_masses
from arcosim.cli.parameters import set_names

#: Methods whose result is a report (``--out`` writes it as JSON), not a time series.
OFFLINE = ("output-error", "whole-chain")
#: Exit status of a fit that was made but is not trusted (its verdict's reasons printed).
EXIT_UNTRUSTED = 3


def check_method_options(args: argparse.Namespace) -> None:
    """Refuse an option given with a method it is not for.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``arcosim identify`` arguments.

    Raises
    ------
    UserError
        When ``--start-k`` or ``--fit-inertia-scale`` comes without ``--method
        output-error``, ``--mode`` without ``--method observer``, or ``--masses``
        that disagrees with the masses of the ``--chain`` file.
    """
    for given, option in (
        (args.start_k is not None, "--start-k"),
        (args.fit_inertia_scale, "--fit-inertia-scale"),
    ):
        if given and args.method != "output-error":
            raise UserError(f"{option} is for --method output-error (not {args.method})")
    if args.mode is not None and args.method != "observer":
        raise UserError(f"--mode is for --method observer (not {args.method})")
    if args.chain and args.masses is not None and args.method not in ("whole-chain", "beam"):
        n = chain_option(args.chain).n
        if masses_option(args.masses) != n:
            raise UserError(
                f"--masses {args.masses} but --chain {args.chain} holds {n}: give one of them"
            )


def masses_option(text: str) -> int:
    """``--masses`` as a supported number of masses.

    Parameters
    ----------
    text : str
        The option's value.

    Returns
    -------
    int
        The number of load masses (a count).

    Raises
    ------
    UserError
        When ``text`` is not a whole number (``auto`` is for ``--method whole-chain``
        only, which reads it before this) or not a supported number of masses.

    Examples
    --------
    >>> masses_option("3")
    3
    """
    try:
        n = int(text)
    except ValueError:
        what = " ('auto' needs --method whole-chain)" if text == "auto" else ""
        raise UserError(f"--masses {text}: not a whole number{what}") from None
    return check_masses(n)


def chain_option(path: Path) -> Chain:
    """``--chain FILE``: the chain of a whole-chain report (:func:`arcosim.read_chain`).

    Parameters
    ----------
    path : Path
        The option's file.

    Returns
    -------
    Chain
        The file's chain: n, every ``J[i]`` (kg·m²), ``k[i]`` (N·m/rad), ``B[i]``
        (N·m·s/rad) and, when there, ``D_m`` (N·m·s/rad) and ``f_c`` (N·m).

    Raises
    ------
    UserError
        What :func:`arcosim.read_chain` raises; a problem with the file's content
        names the option.
    """
    try:
        return read_chain(path)
    except ChainFileError as error:
        raise UserError(f"--chain {error}") from None


def chain_assignments(chain: Chain | None, assignments: Sequence[str]) -> list[str]:
    """The ``--set`` assignments of a chain's values that ``assignments`` do not give.

    Parameters
    ----------
    chain : Chain or None
        The chain of :func:`chain_option`, set as the observer's and the controller's
        parameters (:meth:`~arcosim.fmu.flexchain.chain.Chain.parameters`); None: none.
    assignments : sequence of str
        The user's ``--set`` texts, which win.

    Returns
    -------
    list of str
        ``"NAME=VALUE"`` texts, the value written to round-trip exactly.

    Examples
    --------
    >>> from arcosim.fmu.flexchain.chain import Chain
    >>> chain_assignments(Chain(J=(3e-4,), k=(0.45,), B=(1e-4,)), ["k[1]=0.5"])
    ['J[1]=0.0003', 'B[1]=0.0001']
    """
    if chain is None:
        return []
    given = set_names(assignments)
    return [f"{name}={value!r}" for name, value in chain.parameters().items() if name not in given]


def check_out(args: argparse.Namespace, fmus: Sequence[Path]) -> None:
    """Refuse ``--out`` before any work.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``arcosim identify`` arguments (``out``, ``method``, ``log``,
        ``chain``, ``force``).
    fmus : sequence of Path
        The FMU files the command reads (``--out`` may not be one of them).

    Raises
    ------
    UserError
        A name that does not fit the method's format (a report is ``.json``, outputs
        over time are ``.csv``), an existing file without ``--force``, the log, the
        chain file or an FMU.
    """
    if args.out is None:
        return
    is_json = args.out.suffix.lower() == ".json"
    if args.method == "beam":  # the report (.json) or the tip's motion (.csv)
        if args.out.suffix.lower() not in (".json", ".csv"):
            raise UserError(
                f"--out {args.out}: --method beam writes its report (.json) or the tip's "
                "motion over time (.csv); name a .json or .csv file"
            )
    elif args.method in OFFLINE and not is_json:
        raise UserError(
            f"--out {args.out}: --method {args.method} writes its report as JSON; name a .json file"
        )
    elif is_json and args.method not in OFFLINE:
        raise UserError(
            f"--out {args.out}: --method {args.method} writes its outputs over time as CSV; "
            "name a .csv file (--json prints a summary)"
        )
    chain = [args.chain] if args.chain else []
    check_output(args.out, inputs=[args.log, *chain, *fmus], force=args.force)


def write_report(args: argparse.Namespace, report: Mapping[str, object]) -> None:
    """Refuse a report with a non-finite estimate; write it to ``--out`` if given.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``arcosim identify`` arguments (``log``, ``out``, ``force``).
    report : mapping of str to object
        An offline fit's report; its floats, and those under ``std``, must be finite.

    Raises
    ------
    UserError
        When an estimate or a standard error is not finite (the log does not determine
        it), or ``--out`` cannot be written.
    """
    bad = [
        key
        for key, value in [*report.items(), *dict(report.get("std") or {}).items()]
        if isinstance(value, float) and not math.isfinite(value)
    ]
    if bad:
        raise UserError(
            f"{args.log}: the fit ended on non-finite numbers ({', '.join(bad[:6])}): the log "
            "does not determine them; check --set and the excitation"
        )
    if args.out:
        shown = tool_keys(report) if args.tool_names else report
        write_text(args.out, json.dumps(shown, indent=2) + "\n", force=args.force)
