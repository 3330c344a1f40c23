"""``arcosim check LOG.csv``: can this log support whole-chain identification?

Before any fit: the step's regularity, the motion (the encoder's range, how often the
motor stands still), the excitation's lines against the band the sample rate and the
disturbance observer leave, and the modes the record shows (the weak ones named), each
finding with what would fix it. Exit status 0 when the log can support identification,
1 when it cannot (the reasons printed), 2 for a bad input.

The drive's figures come as the observer's parameters, as for ``arcosim identify``:
``--set k_to=… --set J_mo=… --set encoder_cpr=… [--set g_dist=…]``; any not given
takes the paper bench's value, and the output says so.
"""

from __future__ import annotations

import argparse
import json

from arcosim.cli.options import add_command, log_options
from arcosim.cli.parameters import defaults_note, known_parameters, set_names
from arcosim.identification.log_check import check_log
from arcosim.logs import parse_scales, read_log

#: The drive's figures a check needs, as observer parameter names.
NEEDED = ("k_to", "J_mo", "encoder_cpr")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim check``."""
    p = add_command(
        subparsers,
        "check",
        summary="say whether a log can support identification, before any fit",
        description="""
Before any fit, say whether a log can support whole-chain identification: the
step, the motion the encoder sees, the excitation against the band the sample rate
and the disturbance observer leave, and the modes the record shows, each problem
with what would fix it. Exit status 0: it can; 1: it cannot (reasons printed);
2: a bad input.

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
    p.add_argument("--json", action="store_true", help="print the report as one JSON object")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    log = read_log(args.log, parse_scales(args.scale))
    values = known_parameters(3, args.set)
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
    return 0 if report.ok else 1
