"""Monitor a fleet of drives: identify every axis's logs on Dask and be told which one
drifted.

Three conveyor axes, each a motor driving a belt and a load (two load masses), each
logged on three maintenance dates with the 20 s multi-sine ``arcosim excite`` designs.
On ``conveyor-2`` the belt loses tension: its first spring k[1] is 6 % and then 12 %
lower on the later dates; the other two do not change. The logs come from a small
simulator written here, apart from arcosim's plant FMU: the chain advanced exactly
(zero-order hold through the matrix exponential), the motor's viscous and Coulomb
friction, 5 mA of current noise and a 2000-count encoder.

Then, as an operator would (``arcosim fleet identify FLEET --out STORE``, ``arcosim
fleet drift STORE --plot FIGURES``; here ``arcosim.identify_fleet``, ``arcosim.fleet_drift``
and ``arcosim.fleet_figures``): every log identified on a local Dask cluster of 2
workers into the store, each axis's latest trusted fit compared with its first, the
alarms printed, and the figures drawn.

Run: ``python examples/monitor_a_fleet.py`` (about a minute on two cores; writes into a
temporary folder, or into ``ARCOSIM_EXAMPLE_OUT/fleet-example`` when that is set, and
keeps it there; run again, it identifies nothing new).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np
import scipy.linalg

import arcosim

K_T, J_M = 0.0406, 2.09e-5  # the motor's torque constant (N·m/A) and inertia (kg·m²)
D_M, F_C = 2e-5, 2e-3  # its viscous (N·m·s/rad) and Coulomb (N·m) friction
J, K, B = (4e-4, 8e-4), (0.3, 0.2), (2e-5, 1.5e-5)  # the belt and load: kg·m², N·m/rad, N·m·s/rad
COUNTS, STEP, SECONDS = (
    2000,
    1e-3,
    20.0,
)  # encoder counts per revolution; the log's step, length (s)
DATES = ("2026-01-05", "2026-02-05", "2026-03-05")
BELT = {"conveyor-1": (1.0, 1.0, 1.0), "conveyor-2": (1.0, 0.94, 0.88), "conveyor-3": (1.0,) * 3}


def simulate(k1: float, seed: int) -> dict[str, np.ndarray]:
    """A 20 s log of the drive with first spring ``k1`` (N·m/rad): time (s), i_a (A),
    omega_m (rad/s), theta_m (rad), as the drive records them."""
    inertias, springs, dampers = (J_M, *J), (k1, K[1]), B
    n = len(inertias)
    stiffness, damping = np.zeros((n, n)), np.diag([D_M, 0.0, 0.0])
    for i, (k, b) in enumerate(zip(springs, dampers)):  # spring i joins mass i and i + 1
        for m, sign in ((i, 1.0), (i + 1, -1.0)):
            stiffness[m, i : i + 2] += sign * k * np.array([1.0, -1.0])
            damping[m, i : i + 2] += sign * b * np.array([1.0, -1.0])
    inverse = np.diag(1.0 / np.array(inertias))
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-inverse @ stiffness, -inverse @ damping]])
    b = np.concatenate([np.zeros(n), inverse[:, 0]])  # a torque on the motor
    augmented = np.zeros((2 * n + 1, 2 * n + 1))
    augmented[: 2 * n, : 2 * n], augmented[: 2 * n, 2 * n] = a, b
    hold = scipy.linalg.expm(augmented * STEP)  # exact over a step of constant torque
    phi, gamma = hold[: 2 * n, : 2 * n], hold[: 2 * n, 2 * n]
    time = np.arange(round(SECONDS / STEP) + 1) * STEP
    current = arcosim.multisine(time, 3.0, np.geomspace(3.0, 150.0, 40), seed=seed)
    x, theta = np.zeros(2 * n), np.zeros(len(time))
    for step in range(1, len(time)):
        friction = F_C * np.sign(x[n])  # Coulomb friction, held over the step
        x = phi @ x + gamma * (K_T * current[step - 1] - friction)
        theta[step] = x[0]
    rng = np.random.default_rng(seed)
    count = 2 * np.pi / COUNTS
    encoder = np.floor(theta / count) * count
    return {
        "time": time,
        "i_a": current + 5e-3 * rng.standard_normal(len(time)),
        "omega_m": np.diff(encoder, prepend=0.0) / STEP,
        "theta_m": encoder,
    }


def write_fleet(folder: Path) -> None:
    """The fleet's folder: per axis its ``axis.toml`` and a log per date."""
    for a, (axis, factors) in enumerate(BELT.items()):
        (folder / axis).mkdir(parents=True, exist_ok=True)
        (folder / axis / "axis.toml").write_text(
            f"[set]\nk_to = {K_T}\nJ_mo = {J_M}\nencoder_cpr = {COUNTS}\n", encoding="utf-8"
        )
        for d, (date, factor) in enumerate(zip(DATES, factors)):
            log = simulate(K[0] * factor, seed=10 * a + d)
            arcosim.write_csv(folder / axis / f"{date}.csv", log, force=True)  # the same again


def main(out: Path) -> None:
    write_fleet(out / "fleet")
    print(f"simulated {len(BELT)} axes x {len(DATES)} dates into {out / 'fleet'}")
    run = arcosim.identify_fleet(out / "fleet", out / "store", workers=2)
    print(f"identified {run.identified} logs ({run.failed} failed) in {run.seconds:.0f} s")
    report = arcosim.fleet_drift(out / "store")  # 5 % and 3 standard errors
    for axis, drift in report.axes.items():
        for alarm in drift.alarms:
            print(f"ALARM {axis}: {alarm['parameter']} {alarm['change']:+.1%} "
                  f"({alarm['sigmas']:+.0f} sigma)")  # fmt: skip
        if not drift.alarms:
            print(f"{axis}: no alarm ({len(drift.changes)} parameters compared)")
    for path in arcosim.fleet_figures(report, out / "figures", force=True):
        print(f"wrote {path}")


if __name__ == "__main__":  # Dask's worker processes import this file: run only here
    where = os.environ.get("ARCOSIM_EXAMPLE_OUT")
    if where:
        main(Path(where) / "fleet-example")
    else:
        with tempfile.TemporaryDirectory(prefix="arcosim-fleet-") as temporary:
            main(Path(temporary))
