"""``arcosim identify --method beam``: a flexible link from the hub alone — EI, ρA, the
damping and the hub's friction (or, without the link's length, its modal model), and
the tip's motion over the log (offline).

The link's geometry comes with ``--set`` beside the motor's terms: ``L`` (m) and
``m_tip`` (kg) (what a user knows), ``J_tip`` (kg·m²) and ``r_hub`` (m) (0 unless
given), and ``rhoA`` (kg/m, the link's weighed mass over L), which holds ρA so that EI
is fitted from one clamped mode. ``--out FILE.json`` writes the report (its equivalent
lumped chain at the top, so ``--chain FILE.json`` reads it); ``--out FILE.csv`` writes
``alpha_tip_hat`` (rad), ``w_tip_hat`` (m) and ``tau_reac_hat`` (N·m) over time, with
their units beside it.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence

from arcosim import DriveLog, UserError, identify_link, tool_keys, write_csv
from arcosim.cli.identify.options import write_report
from arcosim.cli.parameters import actuator_of, defaults_note, set_names
from arcosim.host import observer_values

#: The link's ``--set`` names and their units; ``L`` is needed for EI and ρA; ``rhoA``
#: (mass per length, > 0) is held in the fit, not fitted.
GEOMETRY = {"L": "m", "m_tip": "kg", "J_tip": "kg.m2", "r_hub": "m", "rhoA": "kg/m"}
#: The ``--set`` names that must be > 0 (the others ≥ 0).
POSITIVE = ("L", "rhoA")


def split_geometry(assignments: Sequence[str]) -> tuple[dict[str, float], list[str]]:
    """The link's ``--set`` values (:data:`GEOMETRY`) and the other assignments.

    Parameters
    ----------
    assignments : sequence of str
        ``--set`` texts, ``"NAME=VALUE"``.

    Returns
    -------
    tuple of (dict of str to float, list of str)
        The link's values by name (SI units) and the assignments left for the motor.

    Raises
    ------
    UserError
        A link value that is not a finite number, or negative (L: not > 0).

    Examples
    --------
    >>> split_geometry(["L=0.3", "k_to=0.04", "m_tip=0.02"])
    ({'L': 0.3, 'm_tip': 0.02}, ['k_to=0.04'])
    """
    geometry: dict[str, float] = {}
    rest: list[str] = []
    for text in assignments:
        name, _, value = text.partition("=")
        if name.strip() not in GEOMETRY:
            rest.append(text)
            continue
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        low_ok = number > 0 if name.strip() in POSITIVE else number >= 0
        if not (math.isfinite(number) and low_ok):
            bound = "> 0" if name.strip() in POSITIVE else "≥ 0"
            raise UserError(
                f"--set {text}: the link's {name.strip()} must be a number {bound} "
                f"({GEOMETRY[name.strip()]})"
            )
        geometry[name.strip()] = number
    return geometry, rest


def run_beam(args: argparse.Namespace, log: DriveLog) -> int:
    """Identify the flexible link from ``log``; print and write the report or states.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``arcosim identify`` arguments (``set``, ``out``, ``force``,
        ``json``, ``log``, ``tool_names``).
    log : DriveLog
        The checked log, SI units, at a constant step.

    Returns
    -------
    int
        The exit status, 0.

    Raises
    ------
    UserError
        A bad ``--set``, no encoder counts.
    IdentificationError
        A record the fit cannot work with.
    """
    shape, assignments = split_geometry(args.set)
    if "L" not in shape and set(shape) - {"L"}:
        raise UserError(
            "--method beam: --set m_tip, J_tip, r_hub or rhoA need the link's --set L=… (m)"
        )
    rhoA = shape.pop("rhoA", None)
    values = observer_values(1, assignments)
    given = set_names(assignments)
    cpr = int(values["encoder_cpr"])
    if cpr <= 0:
        raise UserError("--method beam needs the encoder's counts: --set encoder_cpr=N")
    what = "EI, ρA and the damping" if rhoA is None else "EI (ρA given) and the damping"
    what = what if "L" in shape else "the link's modal model"
    print(f"arcosim identify: fitting {what} to {len(log)} samples (seconds)…", file=sys.stderr)
    c = log.columns
    result = identify_link(
        log.time,
        c["i_a"],
        c["omega_m"],
        c["theta_m"],
        actuator_of(values),
        encoder_cpr=cpr,
        fit_friction=not {"D_m", "f_c"} <= given,
        rhoA=rhoA,
        **shape,
        g_dist=values["g_dist"],
    )
    note = defaults_note(values, ("J_mo", "k_to", "encoder_cpr"), given)
    if note:
        result = result.with_assumption("defaults", note)
    report = result.to_json()
    if args.out and args.out.suffix.lower() == ".csv":
        write_report(argparse.Namespace(**{**vars(args), "out": None}), report)
        write_csv(
            args.out,
            result.tip_columns(log.time),
            units=result.TIP_UNITS,
            tool_names=args.tool_names,
            force=args.force,
        )
    else:
        write_report(args, report)
    if args.json:
        print(json.dumps(tool_keys(report) if args.tool_names else report, indent=2))
    else:
        print(result.text(len(log)))
    return 0
