"""``arcosim excite``: the excitation to play on a drive for whole-chain identification.

Designs a multi-sine of log-spaced lines over ``--band`` whose amplitudes add up to
``--current-limit`` (a current command; or, with ``--kind speed``, the reference of a
PI speed loop of gain ``--speed-gain``, lines growing with frequency). Writes it as a
CSV (``time`` s and ``i_ref`` A, or ``omega_ref`` rad/s) and prints the
ExcitationSource FMU's parameters that play the same current. Given the drive's
figures (``--k-t``, ``--f-c``, ``--J-total``, ``--encoder-cpr``, ``--g-dist``), the design
is checked against the friction (sticking), the encoder (motion at the top line) and
the band the disturbance observer reads, and warns with what to change.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from arcosim import check_output, design_excitation, write_csv
from arcosim.cli.options import add_command, force_option, number, step_option, whole_number
from arcosim.host import INT_MAX
from arcosim.identification import DURATION, LINES


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim excite``."""
    p = add_command(
        subparsers,
        "excite",
        summary="design the excitation to play on a drive for identification",
        description="""
Design the multi-sine to play on your drive before recording a log for
identification: log-spaced lines over --band (rad/s) within --current-limit (A),
written as a CSV (time, i_ref; or omega_ref with --kind speed), and the
ExcitationSource FMU's parameters that play it. Give the drive's figures (--k-t,
--f-c, --J-total, --encoder-cpr, --g-dist) and the design is checked against
friction, encoder and observer band, with a warning saying what to change.""",
        examples="""
arcosim excite --band 3 150 --current-limit 3 --out excitation.csv
arcosim excite --band 3 150 --current-limit 3 --out excitation.csv \\
    --k-t 0.04 --f-c 0.02 --encoder-cpr 2000""",
    )
    rate = number(0.0, low_open=True, unit="rad/s")
    p.add_argument(
        "--band", nargs=2, type=rate, required=True, metavar=("LOW", "HIGH"), help="rad/s"
    )
    p.add_argument(
        "--current-limit",
        type=number(0.0, 1e6, low_open=True, unit="A"),
        required=True,
        help="the drive's peak current (A)",
    )
    step_option(p)
    p.add_argument(
        "--duration",
        type=number(0.0, 3600.0, low_open=True, unit="s"),
        default=DURATION,
        help=f"record length in s (default {DURATION:g})",
    )
    p.add_argument("--lines", type=whole_number(1, 1000), default=LINES, help=f"default {LINES}")
    p.add_argument("--kind", choices=("current", "speed"), default="current")
    p.add_argument(
        "--speed-gain",
        type=number(0.0, low_open=True, unit="A.s/rad"),
        help="the speed loop's proportional gain (A.s/rad), for --kind speed",
    )
    p.add_argument("--seed", type=whole_number(0, INT_MAX), default=1, help="phases")
    for name, unit, what in (
        ("--k-t", "N.m/A", "torque constant"),
        ("--f-c", "N.m", "Coulomb friction"),
        ("--J-total", "kg.m2", "motor and load inertia"),
        ("--g-dist", "rad/s", "disturbance observer bandwidth"),
    ):
        p.add_argument(name, type=number(0.0, low_open=True, unit=unit), help=f"{what} ({unit})")
    p.add_argument("--encoder-cpr", type=whole_number(1, INT_MAX), help="encoder counts/rev")
    p.add_argument("--out", type=Path, required=True, help="CSV file to write")
    force_option(p)
    p.add_argument("--json", action="store_true", help="print the design as one JSON object")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    check_output(args.out, force=args.force)
    design = design_excitation(
        tuple(args.band),
        args.current_limit,
        h=args.step,
        duration=args.duration,
        lines=args.lines,
        kind=args.kind,
        seed=args.seed,
        k_t=args.k_t,
        f_c=args.f_c,
        J_total=args.J_total,
        encoder_cpr=args.encoder_cpr,
        g_dist=args.g_dist,
        speed_gain=args.speed_gain,
    )
    write_csv(args.out, design.columns(), tool_names=args.tool_names, force=args.force)
    if args.json:
        print(
            json.dumps(
                {
                    "kind": design.kind,
                    "out": str(args.out),
                    "lines_rad_s": design.frequencies.tolist(),
                    "amplitudes": design.amplitudes.tolist(),
                    "source_parameters": design.source_parameters,
                    "warnings": design.warnings,
                },
                indent=2,
            )
        )
        return 0
    unit = "A" if design.kind == "current" else "rad/s"
    print(
        f"wrote {args.out}: {len(design.time)} samples, {len(design.frequencies)} lines "
        f"{design.frequencies[0]:g} … {design.frequencies[-1]:g} rad/s, "
        f"peak {abs(design.signal).max():.3g} {unit}"
    )
    if design.source_parameters:
        settings = ", ".join(f"{k} = {v:g}" for k, v in design.source_parameters.items())
        print(f"the same current from the ExcitationSource FMU's parameters: {settings}")
    for text in design.warnings:
        print(f"warning: {text}")
    return 0
