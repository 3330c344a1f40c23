"""``arcosim identify --method load-torque``: the external torque on one load mass over
time, from the motor alone (the observer's estimator 1 with ``load_mass``, run offline),
the chain from ``--set`` (``--chain``, a whole-chain report, adds its values there):
:func:`arcosim.estimate_load_torque` and its summary.
"""

from __future__ import annotations

import argparse
import json

from arcosim import (
    Chain,
    DriveLog,
    ObserverSettings,
    UserError,
    estimate_load_torque,
    write_csv,
)
from arcosim.cli.parameters import actuator_of, defaults_note, drive_parameters, set_names
from arcosim.fmu.flexchain import Estimator, Mode
from arcosim.host import observer_values


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
    values = observer_values(n, args.set)
    defaults = defaults_note(values, drive_parameters(n), set_names(args.set))
    settings = _settings(values, n)
    c = log.columns
    try:
        result = estimate_load_torque(settings, log.time, c["i_a"], c["omega_m"], c["theta_m"])
    except (ValueError, ZeroDivisionError, OverflowError) as error:  # the Kalman design
        raise UserError(
            f"--method load-torque: no estimator for these settings ({error}); check "
            "torque_noise_std, tau_noise_std, load_torque_bandwidth and the chain"
        ) from None
    if args.out:
        write_csv(args.out, result.columns(), tool_names=args.tool_names, force=args.force)
    if defaults:
        result = result.with_assumption("defaults", defaults)
    if args.json:
        print(json.dumps(result.to_json(), indent=2))
    else:
        print(result.text())
        if args.out:
            print(f"wrote {args.out}")
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
