"""``arcosim check LOG.csv``: can this log support whole-chain identification?

Before any fit, the decisions ``arcosim identify --method whole-chain`` acts on
(:func:`arcosim.identification.checks.log_decision.decide_log`): exit status 0 exactly when
identify fits, 1 when it would refuse (the reasons printed), 2 for a bad input; every
warning printed is one identify gives too. With the figures behind them: the step, the
motion, the excitation (a multi-sine's lines, a periodic reference's harmonics or a
broadband band) and the modes the fit reads.

The drive's figures come as the observer's parameters, as for ``arcosim identify``:
``--set k_to=… --set J_mo=… --set encoder_cpr=… [--set g_dist=…]``; any not given
takes the paper bench's value, and the output says so.
"""

from __future__ import annotations

import argparse
import json

from arcosim import check_log, parse_scales, read_log
from arcosim.cli.identify.options import EXIT_UNTRUSTED, masses_option
from arcosim.cli.options import add_command, log_options
from arcosim.cli.parameters import defaults_note, set_names
from arcosim.host import observer_values

#: The drive's figures a check needs, as observer parameter names.
NEEDED = ("k_to", "J_mo", "encoder_cpr")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim check``."""
    p = add_command(
        subparsers,
        "check",
        summary="say whether a log can support identification, before any fit",
        description="""
Before any fit, say whether whole-chain identification (arcosim identify --method
whole-chain) will fit this log: the same decisions, so exit status 0 exactly when
identify fits, 1 when it would refuse (reasons printed), 2 for a bad input; every
warning is one identify gives too. Shown: the step, the motion the encoder sees, the
excitation (lines, harmonics of a periodic reference, or broadband) and the modes.
Give --masses, --load and the friction (--set D_m=… --set f_c=…) as you will to
identify.

Give first what you know of the motor (anything not given takes the paper bench's
value, and the output says so):
  --set k_to=VALUE        torque constant, N.m/A
  --set J_mo=VALUE        motor inertia, kg.m2
  --set encoder_cpr=N     encoder counts per revolution, after quadrature
  --scale COLUMN=FACTOR   the log's units to SI, e.g. --scale i_a=0.001 for mA""",
        examples="""
arcosim check log.csv --set k_to=0.0406 --set J_mo=2.09e-5 --set encoder_cpr=2000
arcosim check log.csv --scale i_a=0.001 --set k_to=0.0406 --json""",
    )
    log_options(p, "k_to (N.m/A), J_mo (kg.m2), encoder_cpr, g_dist (rad/s); repeatable")
    p.add_argument(
        "--masses",
        default="auto",
        help="the number of load masses identify will be asked for (default auto)",
    )
    p.add_argument(
        "--load",
        choices=("none", "constant", "slow"),
        default="none",
        help="the load torque model identify will be given (default: none given, which "
        "check judges as none and identify chooses by its selection rule)",
    )
    p.add_argument("--json", action="store_true", help="print the report as one JSON object")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    log = read_log(args.log, parse_scales(args.scale))
    values = observer_values(3, args.set)
    given = set_names(args.set)
    c = log.columns
    report = check_log(
        log.time,
        c["i_a"],
        c["omega_m"],
        c["theta_m"],
        k_t=values["k_to"],
        J_m=values["J_mo"],
        encoder_cpr=int(values["encoder_cpr"]),
        g_dist=values["g_dist"],
        masses=args.masses if args.masses == "auto" else masses_option(args.masses),
        load=args.load,
        **({"D_m": values["D_m"], "f_c": values["f_c"]} if {"D_m", "f_c"} <= given else {}),
    )
    note = defaults_note(values, NEEDED, given)
    if args.json:
        out = {k: v for k, v in vars(report).items()}
        out["assumptions"] = {"defaults": note} if note else {}
        print(json.dumps(out, indent=2))
    else:
        print(f"{args.log}: {len(log)} samples")
        print(report.text())
        if note:
            print(f"assumption: {note}")
    if not report.ok:
        return 1
    return EXIT_UNTRUSTED if report.doubts else 0
