"""``arcosim identify --method load-torque``: the external torque on one load mass over
time, from the motor alone (the observer's estimator 1 with ``load_mass``, run offline),
the chain from ``--set`` (``--chain``, a whole-chain report, adds its values there).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from arcosim.cli.parameters import (
    actuator_of,
    defaults_note,
    drive_parameters,
    known_parameters,
    set_names,
)
from arcosim.errors import UserError
from arcosim.fmu.flexchain.chain import Chain
from arcosim.fmu.flexchain.codes import Estimator, Mode
from arcosim.fmu.flexchain.observer import ObserverSettings
from arcosim.identification import load_torque
from arcosim.logs import DriveLog, write_csv


def run_load_torque(args: argparse.Namespace, log: DriveLog, n: int) -> int:
    """Estimate the load torque on mass ``load_mass`` over ``log``; print a summary.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``arcosim identify`` arguments (``set``, ``out``, ``force``, ``json``).
    log : DriveLog
        The checked log, SI units; the step may vary.
    n : int
        Number of load masses (a count).

    Returns
    -------
    int
        The exit status, 0.

    Raises
    ------
    UserError
        No ``load_mass`` in 1 … n, a chain or tuning no estimator can be designed for.
    """
    values = known_parameters(n, args.set)
    defaults = defaults_note(values, drive_parameters(n), set_names(args.set))
    settings = _settings(values, n)
    c = log.columns
    try:
        result = load_torque.estimate_load_torque(
            settings, log.time, c["i_a"], c["omega_m"], c["theta_m"]
        )
    except (ValueError, ZeroDivisionError, OverflowError) as error:  # the Kalman design
        raise UserError(
            f"--method load-torque: no estimator for these settings ({error}); check "
            "torque_noise_std, tau_noise_std, load_torque_bandwidth and the chain"
        ) from None
    if args.out:
        write_csv(args.out, result.columns(), tool_names=args.tool_names, force=args.force)
    last = log.time >= log.time[-1] - 1.0
    report = {
        "method": "load-torque",
        "masses": n,
        "load_mass": settings.load_mass,
        "load_torque_bandwidth": settings.load_torque_bandwidth,
        "samples": len(log),
        "final": float(result.tau_load[-1]),
        "mean_last_second": float(np.mean(result.tau_load[last])),
        "std_last_second": float(np.std(result.tau_load[last])),
        "rms_innovation": float(np.sqrt(np.mean(result.innovation**2))),
    }
    if defaults:
        report["assumptions"] = {"defaults": defaults}
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        _print_report(report, args.out)
    return 0


def _settings(values: dict[str, float], n: int) -> ObserverSettings:
    """The observer's settings for the offline estimator; refuse what it cannot run."""
    load_mass = int(values["load_mass"])
    if not 1 <= load_mass <= n:
        raise UserError(
            f"--method load-torque needs the load mass: --set load_mass=I with I in 1 … {n} "
            f"(got {load_mass})"
        )
    try:
        chain = Chain.from_parameters(values, n=n)
    except ValueError as error:
        raise UserError(str(error).removeprefix("Chain: ")) from None
    settings = ObserverSettings.for_chain(
        chain,
        actuator=actuator_of(values),
        mode=Mode.STATE_ESTIMATION,
        g_dist=values["g_dist"],
        g_lpf=values["g_lpf"],
        estimator=Estimator.MODEL_BASED,
        encoder_cpr=int(values["encoder_cpr"]),
        torque_noise_std=values["torque_noise_std"],
        tau_noise_std=values["tau_noise_std"],
        load_mass=load_mass,
        load_torque_bandwidth=values["load_torque_bandwidth"],
    )
    if not settings.load_torque_bandwidth > 0:
        raise UserError("load_torque_bandwidth must be > 0 (rad/s)")
    return settings


def _print_report(report: dict, out: Path | None) -> None:
    """The summary as text, and the file written."""
    print(
        f"{report['samples']} samples, load torque on mass {report['load_mass']} of "
        f"{report['masses']} (bandwidth {report['load_torque_bandwidth']:g} rad/s):"
    )
    print(f"  final              {report['final']:.6g} N·m")
    print(
        f"  last second        {report['mean_last_second']:.6g} ± "
        f"{report['std_last_second']:.2g} N·m (mean ± std)"
    )
    print(f"  rms innovation     {report['rms_innovation']:.3g} N·m")
    if "assumptions" in report:
        print(f"  assumption, defaults: {report['assumptions']['defaults']}")
    if out:
        print(f"wrote {out}")
