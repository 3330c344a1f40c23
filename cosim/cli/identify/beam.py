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
from dataclasses import replace

import numpy as np

from arcosim.cli.identify.options import write_report
from arcosim.cli.parameters import actuator_of, defaults_note, known_parameters, set_names
from arcosim.errors import UserError
from arcosim.identification.checks.log_check import log_plausibility
from arcosim.identification.checks.noise_floor import floor_warning, noise_floor
from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.motor_friction import without_friction
from arcosim.identification.fit.output_error import ParameterFit, predict
from arcosim.identification.link.beam_fit import Geometry, fit_link, fit_modes, modal_of
from arcosim.identification.link.beam_model import ModalModel, observer_parameters
from arcosim.identification.link.beam_motion import link_assumptions, stiffening_warning, tip_motion
from arcosim.identification.records.record import (
    EncoderRecord,
    MotorRecord,
    encoder_record,
    motor_record,
)
from arcosim.logs import DriveLog, tool_keys, write_csv

#: The link's ``--set`` names and their units; ``L`` is needed for EI and ρA; ``rhoA``
#: (mass per length, > 0) is held in the fit, not fitted.
GEOMETRY = {"L": "m", "m_tip": "kg", "J_tip": "kg.m2", "r_hub": "m", "rhoA": "kg/m"}
#: The ``--set`` names that must be > 0 (the others ≥ 0).
POSITIVE = ("L", "rhoA")
#: Units of the columns ``--out FILE.csv`` writes.
STATE_UNITS = {"time": "s", "alpha_tip_hat": "rad", "w_tip_hat": "m", "tau_reac_hat": "N.m"}


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
        A bad ``--set``, no encoder counts, a record the fit cannot work with, a fit
        that ends on non-finite numbers.
    """
    shape, assignments = split_geometry(args.set)
    if "L" not in shape and set(shape) - {"L"}:
        raise UserError(
            "--method beam: --set m_tip, J_tip, r_hub or rhoA need the link's --set L=… (m)"
        )
    rhoA = shape.pop("rhoA", None)
    values = known_parameters(1, assignments)
    given = set_names(assignments)
    friction_given = {"D_m", "f_c"} <= given
    actuator = actuator_of(values)
    if not friction_given:  # fitted: τ̂ (the start's modes) is computed without it
        actuator = replace(actuator, D_m=0.0, f_c=0.0)
    cpr = int(values["encoder_cpr"])
    if cpr <= 0:
        raise UserError("--method beam needs the encoder's counts: --set encoder_cpr=N")
    c = log.columns
    k_t, J_m = actuator.k_to + actuator.dkt, actuator.J_mo + actuator.dJm
    plausibility = log_plausibility(log.time, c["i_a"], c["omega_m"], c["theta_m"], k_t, J_m)
    motor = motor_record(log.time, c["i_a"], c["omega_m"], c["theta_m"], actuator, values["g_dist"])
    encoder = encoder_record(
        log.time, c["i_a"], c["theta_m"], actuator, cpr, friction_given, "none", values["g_dist"]
    )
    geometry = Geometry(**shape) if "L" in shape else None
    what = "EI, ρA and the damping" if rhoA is None else "EI (ρA given) and the damping"
    what = what if geometry else "the link's modal model"
    print(f"arcosim identify: fitting {what} to {len(log)} samples (seconds)…", file=sys.stderr)
    try:
        result = _fit(encoder, motor, geometry, rhoA)
    except IdentificationError as error:
        if not plausibility:
            raise
        raise IdentificationError(f"{'; '.join(plausibility)}; the fit: {error}") from error
    model = modal_of(result, geometry) if geometry else _modes_of(result)
    D_m, f_c = result.extra["D_m"], result.extra["f_c"]
    chain = result.extra["chain"]
    n = int(chain["masses"])
    J, k, B = ([chain[f"{p}[{i}]"] for i in range(1, n + 1)] for p in "JkB")
    if not friction_given:  # τ̂ was computed without it: the fitted friction out
        motor = without_friction(motor, encoder, D_m, f_c)
    residual = predict(motor, J, k, B) - motor.tau_hat
    rms = float(np.sqrt(np.mean(residual**2)))
    floor, sigma_i = noise_floor(log.time, c["i_a"], (J, k, B), k_t, J_m, cpr, values["g_dist"])
    warnings = list(plausibility) + list(result.extra.get("warnings", []))
    for text in (
        stiffening_warning(encoder.velocity, float(model.frequency[0])),
        floor_warning(rms, floor, sigma_i),
    ):
        if text:
            warnings.append(text)
    assumptions = link_assumptions(geometry, rhoA)
    note = defaults_note(values, ("J_mo", "k_to", "encoder_cpr"), given)
    if note:
        assumptions["defaults"] = note
    report = _report(result, model, geometry, assumptions, warnings, rms, motor.duration)
    report.update(D_m=D_m, f_c=f_c)
    if args.out and args.out.suffix.lower() == ".csv":
        tip = tip_motion(encoder, model, D_m, f_c)
        columns = {
            "time": log.time,
            "alpha_tip_hat": tip.alpha_tip,
            "w_tip_hat": tip.w_tip,
            "tau_reac_hat": tip.tau_reac,
        }
        write_report(argparse.Namespace(**{**vars(args), "out": None}), report)
        write_csv(
            args.out, columns, units=STATE_UNITS, tool_names=args.tool_names, force=args.force
        )
    else:
        write_report(args, report)
    if args.json:
        print(json.dumps(tool_keys(report) if args.tool_names else report, indent=2))
    else:
        _print_report(report, len(log))
    return 0


def _fit(
    encoder: EncoderRecord, motor: MotorRecord, geometry: Geometry | None, rhoA: float | None
) -> ParameterFit:
    """EI (ρA unless given, kg/m) and the damping with the geometry, else the modal model."""
    if geometry is None:
        return fit_modes(encoder, motor)
    return fit_link(encoder, motor, geometry, rhoA=rhoA)


def _modes_of(result: ParameterFit) -> ModalModel:
    """The modal model of :func:`fit_modes`' result (no tip shape: L unknown)."""
    values = result.as_dict()
    count = sum(name.startswith("omega[") for name in result.names)
    pick = [np.array([values[f"{p}[{i}]"] for i in range(1, count + 1)]) for p in ("omega", "b")]
    zeta = np.array([values[f"zeta[{i}]"] for i in range(1, count + 1)])
    J_link = float(np.sum(pick[1] ** 2)) + values["J_rest"]
    return ModalModel(pick[0], pick[1], np.zeros(count), zeta, J_link, 1.0)


def _report(
    result: ParameterFit,
    model: ModalModel,
    geometry: Geometry | None,
    assumptions: dict[str, str],
    warnings: list[str],
    rms: float,
    duration: float,
) -> dict[str, object]:
    """Everything, JSON-able: the fit, the modal model, the equivalent chain (also at the
    top, as ``--chain`` reads it), assumptions and warnings."""
    extra = result.extra
    chain = extra["chain"]
    out: dict[str, object] = {"method": "beam"}
    out.update(result.as_dict())
    out["std"] = result.std_dict()
    out.update(
        modes_rad_s=[float(w) for w in model.frequency],
        damping_ratios=[float(z) for z in model.damping],
        participation=[float(b) for b in model.participation],
        J_link=float(model.J_link),
        J_rest=float(model.J_rest),
    )
    if geometry is not None:
        rhoA = extra.get("rhoA_given")
        if rhoA is not None:  # given, held: a value without a standard error
            out.update(rhoA=rhoA, rhoA_given=True)
        out.update(
            L=geometry.L,
            m_tip=geometry.m_tip,
            J_tip=geometry.J_tip,
            r_hub=geometry.r_hub,
            tip_shape_m=[float(p) for p in model.tip],
            observer_parameters=observer_parameters(model),
        )
    out.update(
        equivalent_chain=dict(chain),
        start=result.start_note,
        rms_innovation=result.rms_residual,
        rms_residual=rms,
        newey_west_lag=result.lag,
        duration=duration,
        evaluations=result.evaluations,
        detected_modes_rad_s=extra.get("detected_modes_rad_s", extra.get("modes_rad_s")),
        assumptions=assumptions,
        warnings=warnings,
    )
    out.update(chain)  # J[i], k[i], B[i], masses: what --chain reads
    return out


def _print_report(report: dict, samples: int) -> None:
    """The report as text."""
    print(f"{samples} samples, flexible link ({report['method']}):")
    std = report["std"]
    for key, value in std.items():
        print(f"  {key:9s} {report[key]:.6g}  ± {value:.2g}")
    for key in ("modes_rad_s", "damping_ratios", "participation", "J_link", "start"):
        print(f"  {key}: {report[key]}")
    for key, text in report["assumptions"].items():
        print(f"  assumption, {key}: {text}")
    for text in report["warnings"]:
        print(f"  warning: {text}")
    chain = report["equivalent_chain"]
    line = " ".join(f"{k}={v:.4g}" for k, v in chain.items() if k != "masses")
    print(f"  equivalent chain ({chain['masses']} masses, --chain reads it): {line}")
