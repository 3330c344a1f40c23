"""``arcosim control [--chain FIT.json]``: the motion controller for a chain, checked
before it runs.

Designs the sensorless controller as the ``ActionReactionController`` FMU does at
initialization (the same code) for the chain and the goals given with the FMU's own
parameter names, and prints both loops' margins (:func:`arcosim.control.controller_margins`):
the full-state loop's (the upper bound) and the sensorless loop's, linearized, with the
model exact, one step late and with every J_i, k_i scaled within ``--error`` of the
chain's. Exit status 0 when the sensorless loop decays in every case, 1 when some case
grows (the verdict says which, and within which smaller error it would not), 2 for a bad
input. Parameters not given take the FMU's defaults (the paper bench's), and the output
says which.
"""

from __future__ import annotations

import argparse
import json
import sys

from arcosim import Chain, UserError, controller_margins
from arcosim.cli.identify.options import chain_assignments, chain_option, masses_option
from arcosim.cli.options import add_command, number
from arcosim.cli.parameters import defaults_note, drive_parameters, set_names
from arcosim.control import ERROR, RANDOM_MODELS
from arcosim.fmu.flexchain import STEP
from arcosim.host import controller_problems, controller_values

#: The goals among the controller's parameters (the rest describe the drive).
GOALS = ("control_mass", "move_time", "bandwidth", "i_max", "hold_dither")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim control``."""
    p = add_command(
        subparsers,
        "control",
        summary="design the motion controller for a chain and check its margins",
        description=f"""
Design the sensorless motion controller (the ActionReactionController FMU's own design)
for a chain and goals, and check both of its loops before it runs: the full-state
loop's margins (phase, delay, max |S|: the upper bound) and the sensorless loop's
slowest decay, linearized (exact encoder, no Coulomb friction), with the model exact, one
step late (a parallel master) and with every J_i, k_i scaled within --error of the
chain's ({RANDOM_MODELS} random models and the two corners: all J +e with all k -e, and
the reverse). The chain given is taken as the truth: "if my identified chain were this
far off, would the loop still decay?". Exit status 0 when it decays in every case, 1
when some case decays slower than 0.1 1/s or grows (the verdict names it), 2 for a bad
input. It simulates 24 moves or more: about 20 s for one mass, 30 s for three, 50-60 s
for five and 2 min for ten on a 2-core machine, more for twenty (a line on stderr says so).

The chain and the goals under the controller FMU's parameter names:
  --chain FIT.json            J[i], k[i], B[i], D_m, f_c and the masses of a
                              whole-chain report (arcosim identify --method
                              whole-chain --out FIT.json); --set wins
  --set J_mo=VALUE            motor inertia, kg.m2 (also k_to N.m/A, D_m N.m.s/rad,
                              f_c N.m, J[i], k[i], B[i], g_dist rad/s, encoder_cpr)
  --set move_time=T           s, or --set move_time=0 --set bandwidth=W (rad/s)
  --set control_mass=L        the load mass moved (default the last)
Anything not given takes the FMU's default (the paper bench's), and the output says so.""",
        examples="""
arcosim control --chain chain.json --set J_mo=2.09e-5 --set k_to=0.0406
arcosim control --masses 2 --set move_time=0.8 --json""",
    )
    p.add_argument(
        "--chain", metavar="FIT.json", help="a whole-chain report to read the chain from"
    )
    p.add_argument(
        "--masses",
        metavar="N",
        help="the number of load masses when no --chain gives it (default 3, the bench's)",
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a controller FMU parameter, in its unit; repeatable",
    )
    p.add_argument(
        "--step",
        type=number(0.0, 0.1, low_open=True, unit="s"),
        default=STEP,
        metavar="H",
        help=f"the control step in s, > 0 and <= 0.1 (default {STEP:g}); refused when "
        "too coarse for the bandwidth or the chain's fastest mode",
    )
    p.add_argument(
        "--error",
        type=number(0.0, 1.0, low_open=True),
        default=ERROR,
        metavar="E",
        help=f"the relative model error checked, 0 < E < 1 (default {ERROR:g}: "
        f"±{100 * ERROR:g} %%)",
    )
    p.add_argument("--json", action="store_true", help="print the report as one JSON object")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    chain = chain_option(args.chain) if args.chain else None
    n = _masses(args, chain)
    assignments = [*chain_assignments(chain, args.set), *args.set]
    values = controller_values(n, assignments)
    problems = controller_problems(n, values)
    if problems:
        raise UserError("; ".join(problems))
    goals = {name: values[name] for name in GOALS}
    goals["control_mass"] = int(goals["control_mass"])
    if not args.error < 1.0:
        raise UserError(f"--error {args.error:g}: give 0 < E < 1 (0.1 for ±10 %)")
    try:
        found = controller_margins(
            values, h=args.step, error=args.error, started=lambda: _status(n), **goals
        )
    except ValueError as error:
        raise UserError(str(error)) from None
    note = defaults_note(values, drive_parameters(n), set_names(assignments))
    if args.json:
        out = found.as_dict()
        out["assumptions"] = {"defaults": note} if note else {}
        print(json.dumps(out, indent=2, allow_nan=False))
    else:
        print(f"controller for {n} load mass{'es' if n > 1 else ''}"
              + (f" from {args.chain}" if args.chain else ""))  # fmt: skip
        print(found.text())
        if note:
            print(f"assumption: {note}")
    return 0 if found.robust else 1


def _status(n: int) -> None:
    """The line on stderr before the runs, which take seconds (stdout stays the report's)."""
    print(
        f"arcosim control: simulating {RANDOM_MODELS + 4} moves of the {n}-mass loop and "
        "linearizing each (about a minute for five masses)…",
        file=sys.stderr,
        flush=True,
    )


def _masses(args: argparse.Namespace, chain: Chain | None) -> int:
    """n from the chain file, else ``--masses``, else 3; refuse both disagreeing."""
    given = None if args.masses is None else masses_option(args.masses)
    if chain is None:
        return 3 if given is None else given
    n = chain.n
    if given is not None and given != n:
        raise UserError(f"--masses {given} but --chain {args.chain} holds {n}: give one of them")
    return n
