"""Identify your drive: from a log of the motor's current and encoder to every inertia,
stiffness and damping of its load chain, then the load's angle with no sensor there.

The log here, ``data/belt_drive.csv``, is a belt drive the project was never tuned on
(a motor, a pulley and a load on a belt: two load masses), recorded the way a drive
records it: current in mA, the encoder's angle in counts and its speed in counts per
second, one row per millisecond, 20 s of the multi-sine that

    arcosim excite --band 3 150 --current-limit 3 --out excitation.csv

designs. Your own log needs the same four columns (any units: step 1 says how to scale
them) and the motor's datasheet values: its torque constant and its inertia.

Run: ``python examples/identify_your_drive.py`` (writes nothing unless
``ARCOSIM_EXAMPLE_OUT`` names a folder for the estimate's CSV).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

import arcosim

LOG = Path(__file__).parent / "data" / "belt_drive.csv"
COUNTS = 2000  # the encoder's counts per revolution (after quadrature)
K_T = 0.0406  # the motor's torque constant (N·m/A), from its datasheet
J_M = 2.09e-5  # the motor's inertia (kg·m²), from its datasheet


def main() -> None:
    # 1. Read the log, scaled to SI units: mA → A, counts → rad, counts/s → rad/s.
    radians_per_count = 2.0 * math.pi / COUNTS
    log = arcosim.read_log(
        LOG, {"i_a": 1e-3, "theta_m": radians_per_count, "omega_m": radians_per_count}
    )
    signals = [log.columns[c] for c in ("i_a", "omega_m", "theta_m")]
    print(f"1. {LOG.name}: {len(log)} samples, {log.time[-1]:.1f} s")

    # 2. Before any fit: can this log support identification?
    report = arcosim.check_log(log.time, *signals, k_t=K_T, J_m=J_M, encoder_cpr=COUNTS)
    print("2. check:\n   " + report.text().replace("\n", "\n   "))
    if not report.ok:
        raise SystemExit("the log cannot support identification: see the problems above")

    # 3. Identify the whole chain: the number of masses, every J_i, k_i, B_i, and the
    #    motor's friction (not given, so fitted), each with its standard error.
    result = arcosim.identify_drive(
        log.time, *signals, k_t=K_T, J_m=J_M, encoder_cpr=COUNTS, masses="auto"
    )
    print(f"3. identified {result.masses} load masses, verdict: {result.verdict.word}")
    for reason in result.verdict.reasons:  # each names what to check
        print(f"   reason: {reason}")
    for name, value in result.parameters.items():
        print(f"   {name:8s} {value:.5g} ± {result.std[name]:.2g}")
    for key, text in result.assumptions.items():
        print(f"   assumption, {key}: {text}")
    if not result.verdict.trusted:
        raise SystemExit("the fit is not trusted: answer the reasons above first")
    if not result.verdict.trusted:
        raise SystemExit("the fit is not trusted: answer the reasons above first")

    # 4. Estimate every load angle from the motor alone: the observer FMU in mode 2,
    #    model-based estimator, with the chain just identified.
    folder = arcosim.ensure_built(result.masses)
    #    (observer_parameters: the chain, the friction and estimator = 1.)
    parameters = {"mode": 2, "encoder_cpr": COUNTS, "J_mo": J_M, "k_to": K_T}
    parameters.update(result.observer_parameters())
    with arcosim.FmuInstance(folder / "ReactionTorqueObserver.fmu", "observer") as observer:
        estimate = arcosim.replay_log(observer, log, parameters)
    print(f"4. the observer FMU replayed the log with {len(parameters)} parameters set")

    # 5. The sample log also holds the truth the drive could not measure: score the
    #    estimate as rms(θ̂_i − θ_i) / rms(θ_i − θ_m) (0 is perfect, θ̂_i = θ_m scores 1).
    raw = np.genfromtxt(LOG, delimiter=",", names=True)
    motor = log.columns["theta_m"]
    print("5. load angles from the motor alone, error relative to the flexible motion:")
    for i in range(1, result.masses + 1):
        estimated = estimate.signals[f"observer.theta_hat[{i}]"]
        true = raw[f"theta_{i}_true"]
        score = np.sqrt(np.mean((estimated - true) ** 2) / np.mean((true - motor) ** 2))
        print(f"   mass {i}: {100 * score:.1f} %")

    out = os.environ.get("ARCOSIM_EXAMPLE_OUT")
    if out:
        path = Path(out) / "belt_drive_estimate.csv"
        columns = {"time": estimate.time}
        columns.update({k.split(".", 1)[1]: v for k, v in estimate.signals.items()})
        arcosim.write_csv(path, columns, force=True)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
