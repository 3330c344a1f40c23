"""``arcosim identify --method output-error``: the paper's uniform chain, k and B (and a
common scale on the J_i) fitted offline to τ̂_reac, and the report of the fit.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence

from arcosim.cli.identify.options import write_report
from arcosim.cli.parameters import actuator_of, defaults_note, known_parameters, set_names
from arcosim.errors import UserError
from arcosim.identification.fit.output_error import ParameterFit
from arcosim.identification.fit.uniform_fit import clamped_frequencies, uniform_chain
from arcosim.identification.records.record import MotorRecord, motor_record
from arcosim.logs import DriveLog, tool_keys

#: The report's names of the fit's parameters.
REPORT_NAMES = {"k": "k_hat", "B": "B_hat", "J_scale": "J_scale"}


def run_output_error(args: argparse.Namespace, log: DriveLog, n: int) -> int:
    """Fit the uniform chain of ``n`` masses to ``log``; print and write the report.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``arcosim identify`` arguments (``set``, ``start_k``,
        ``fit_inertia_scale``, ``out``, ``force``, ``json``, ``log``).
    log : DriveLog
        The checked log, SI units, at a constant step.
    n : int
        Number of load masses (a count).

    Returns
    -------
    int
        The exit status, 0.

    Raises
    ------
    UserError
        Load inertias not > 0, a ``--start-k`` out of the log's band, a fit that ends
        on non-finite numbers.
    """
    values = known_parameters(n, args.set)
    J = [values[f"J[{i}]"] for i in range(1, n + 1)]
    if any(not x > 0 for x in J):
        raise UserError(f"the load inertias must be > 0, got J = {J}")
    c = log.columns
    record = motor_record(
        log.time, c["i_a"], c["omega_m"], c["theta_m"], actuator_of(values), values["g_dist"]
    )
    if args.start_k is not None:
        check_start_k(args.start_k, J, record)
    result = uniform_chain(record, J, args.fit_inertia_scale, args.start_k)
    report = {REPORT_NAMES[k]: v for k, v in result.as_dict().items()}
    report["std"] = {REPORT_NAMES[k]: v for k, v in result.std_dict().items()}
    report.update(evidence(result, record))
    known = ["J_mo", "k_to", "D_m", "f_c", *(f"J[{i}]" for i in range(1, n + 1))]
    defaults = defaults_note(values, known, set_names(args.set))
    if defaults:
        report["assumptions"] = {"defaults": defaults}
    write_report(args, report)
    if args.json:
        print(json.dumps(tool_keys(report) if args.tool_names else report, indent=2))
    else:
        _print_report(report, len(log), n, defaults)
    return 0


def _print_report(report: dict, samples: int, n: int, defaults: str | None) -> None:
    """The report as text: the estimates with their standard errors, then the evidence."""
    print(f"{samples} samples, output-error fit of the uniform chain ({n} masses):")
    for key in (k for k in report if k in REPORT_NAMES.values()):
        print(f"  {key:8s} {report[key]:.6g}  ± {report['std'][key]:.2g}")
    for key in ("start", "velocity", "rms_residual", "rms_data", "newey_west_lag"):
        print(f"  {key}: {report[key]}")
    if defaults:
        print(f"  assumption, defaults: {defaults}")


def check_start_k(k: float, J: Sequence[float], record: MotorRecord) -> None:
    """Refuse a ``--start-k`` whose chain's first mode the record cannot show.

    Parameters
    ----------
    k : float
        The start stiffness (N·m/rad).
    J : sequence of float
        The load inertias (kg·m²), shape ``(n,)``.
    record : MotorRecord
        The record the fit runs on (its length and step).

    Raises
    ------
    UserError
        When the uniform chain's first clamped mode lies outside the band from one
        period in the record's length to the Nyquist frequency π/h.
    """
    unit = float(clamped_frequencies([float(x) for x in J], [1.0] * len(J))[0])
    low_w, high_w = 2.0 * math.pi / record.duration, math.pi / record.h
    low, high = (low_w / unit) ** 2, (high_w / unit) ** 2
    if not low <= k <= high:
        raise UserError(
            f"--start-k {k:g}: give a stiffness from {low:.3g} to {high:.3g} N.m/rad for this "
            f"log and J (the chain's first mode between one period in {record.duration:g} s, "
            f"{low_w:.3g} rad/s, and the Nyquist frequency, {high_w:.3g} rad/s)"
        )


def evidence(result: ParameterFit, record: MotorRecord) -> dict[str, object]:
    """What an output-error fit rests on, for the JSON report.

    Parameters
    ----------
    result : ParameterFit
        The fit.
    record : MotorRecord
        The record it ran on.

    Returns
    -------
    dict of str to object
        ``method``, ``start``, ``velocity``, ``rms_residual`` and ``rms_data`` (N·m),
        ``newey_west_lag`` (samples, a count), ``duration`` (s), ``evaluations`` (a count).
    """
    return {
        "method": "output-error",
        "start": result.start_note,
        "velocity": record.velocity_source,
        "rms_residual": result.rms_residual,
        "rms_data": result.rms_data,
        "newey_west_lag": result.lag,
        "duration": record.duration,
        "evaluations": result.evaluations,
    }
