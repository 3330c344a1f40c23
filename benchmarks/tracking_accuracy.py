"""``arcosim bench tracking``: the observer FMU's tracker (``tracking = 1``) on drives that
wear while they work.

The plant is :mod:`benchmarks.simulators.field_sim` (written apart from the plant FMU:
Coulomb friction with sticking, a 2000-count encoder, current noise 5 mA), its springs
and friction changed over time through its ``drift`` hook; the observer FMU replays its
log (:func:`arcosim.host.tracking.replay_tracking`) with the commissioning chain as its
parameters. Operations:

- ``position``: back-and-forth moves of 1 rad in 1 s (a cycloid), 1 s dwell, in a P
  position loop around a PI speed loop on the encoder (no added excitation);
- ``speed``: the PI speed loop following a trapezoid, ±5 rad/s, 1 s ramps, 2 s holds;
- ``conveyor``: constant 5 rad/s with load steps of ±10 mN·m on the last mass every 10 s.

Rows, each on the two-mass and the three-mass chain:

- ``k``: k_1 falls 10 % over 150 s (from t = 20 s), the run ends 50 s after: the tracked
  k_1 against the truth at the end, the alarm, its time after the drift began;
- ``friction``: f_c doubles over 150 s, the same;
- ``healthy``: nothing changes: alarms raised after the first 60 s (the false alarms),
  the tracked k's largest error and spread after it;
- ``constant``: the conveyor, healthy: the share of samples with ``tracking_valid`` = 1
  and the alarms.

``--cost`` measures the observer FMU's per-step time through fmpy with tracking on and
off, for 2, 3 and 5 masses.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from arcosim import DriveLog, FmuInstance
from arcosim.build import OBSERVER
from arcosim.fmu.flexchain import defaults
from arcosim.host import TrackedChain, replay_tracking
from benchmarks import progress
from benchmarks.simulators import field_sim

H = 1e-3  #: sample step (s)
DRIFT_START = 20.0  #: the wear begins (s) …
DRIFT_TIME = 150.0  #: … lasts this long (s) …
AFTER = 50.0  #: … and the run ends this long after it (s)
WARM_UP = 60.0  #: alarms in the first tracking_time are not counted as false (s)
HEALTHY = 300.0  #: a healthy run's length (s; ``--healthy`` sets it)
K_DROP = 0.10  #: k_1 falls by this share
FRICTION_GAIN = 2.0  #: f_c is multiplied by this
SPEED = 5.0  #: the speed loop's and the conveyor's speed (rad/s)
LOAD_STEP = 0.01  #: the conveyor's load steps (N·m)
#: Per chain, the speed loop (kp A·s/rad, ki A/rad) and the position loop's gain (1/s): a
#: speed loop of about 10 rad/s on the two-mass chain's 1 g·m², the position loop a half
#: of it. On the two-mass chain the PI's corner ki/kp (5 rad/s) equals the position
#: loop's gain, so the drive hunts (about 100 reversals in 20 s of five moves); a calmer
#: loop (ki 0.2) took its tracked stiffnesses 20–28 % off: the tracker lives on the
#: excitation the hunting gives, so its rows keep this loop and say so. On the
#: three-mass chain the same loop grows into a limit cycle of ±10 rad; there the
#: corner is put below the position loop's gain, as a cascade's inner integral must be
#: (ki 0.2: 2 rad/s), and the moves settle (0.24 rad rms off the reference, as the
#: two-mass chain's hunting loop).
LOOPS = {"two-mass": (0.1, 0.5, 5.0), "three-mass": (0.1, 0.2, 5.0)}

CHAINS = {
    "two-mass": (tuple(defaults.inertias(2)), (defaults.K,) * 2, (defaults.B,) * 2),
    "three-mass": (tuple(defaults.inertias(3)), (defaults.K,) * 3, (defaults.B,) * 3),
}


def moves(t: np.ndarray) -> np.ndarray:
    """Back-and-forth moves: 1 rad in 1 s (a cycloid), 1 s dwell, back (rad)."""
    phase = np.mod(np.asarray(t, float), 4.0)
    up, down = np.clip(phase, 0.0, 1.0), np.clip(phase - 2.0, 0.0, 1.0)

    def cycloid(x: np.ndarray) -> np.ndarray:
        return x - np.sin(2 * np.pi * x) / (2 * np.pi)

    return cycloid(up) - cycloid(down)


def trapezoid(t: np.ndarray) -> np.ndarray:
    """±SPEED with 1 s ramps and 2 s holds, period 6 s (rad/s)."""
    phase = np.mod(np.asarray(t, float), 6.0)
    rising = np.clip(phase, 0.0, 1.0) - np.clip(phase - 3.0, 0.0, 1.0) * 2.0
    falling = np.clip(phase - 5.0, 0.0, 1.0)
    return SPEED * (rising + falling)


def constant(t: np.ndarray) -> np.ndarray:
    """SPEED after a 1 s ramp (rad/s)."""
    return SPEED * np.minimum(np.asarray(t, float), 1.0)


def loop(chain: str, operation: str) -> field_sim.SpeedLoop:
    """The drive's controller for an operation on a chain."""
    kp, ki, position_gain = LOOPS[chain]
    if operation == "position":
        return field_sim.SpeedLoop(kp, ki, moves, limit=10.0, position_gain=position_gain)
    return field_sim.SpeedLoop(kp, ki, trapezoid if operation == "speed" else constant, 10.0)


def plant(chain: str) -> field_sim.Drive:
    """The commissioning drive of a chain, with the realistic sensors."""
    J, k, B = CHAINS[chain]
    return field_sim.Drive(
        J_m=defaults.J_M, k_t=defaults.K_T, J=J, k=k, B=B, D_m=defaults.D_M, f_c=defaults.F_C,
        current_noise=0.005, counts=2000,
    )  # fmt: skip


def ramp(t: float) -> float:
    """The wear's progress at ``t`` (s): 0 before, 1 after the drift (dimensionless)."""
    return min(max((t - DRIFT_START) / DRIFT_TIME, 0.0), 1.0)


def wear(row: str, drive: field_sim.Drive, operation: str) -> Callable[[float], field_sim.Drive]:
    """The drive at time t for a row (and the conveyor's load steps)."""

    def at(t: float) -> field_sim.Drive:
        k, f_c = list(drive.k), drive.f_c
        if row == "k":
            k[0] *= 1.0 - K_DROP * ramp(t)
        elif row == "friction":
            f_c *= 1.0 + (FRICTION_GAIN - 1.0) * ramp(t)
        load = LOAD_STEP * (int(t // 10.0) % 2) if operation == "conveyor" else 0.0
        return dataclasses.replace(drive, k=tuple(k), f_c=f_c, load_torque=load)

    return at


def duration(row: str, healthy: float) -> float:
    """A row's run (s)."""
    return DRIFT_START + DRIFT_TIME + AFTER if row in ("k", "friction") else healthy


def run(chain: str, operation: str, row: str, healthy: float, folder: Path) -> dict:
    """One run: simulate, replay through the observer FMU, score."""
    drive = plant(chain)
    length = duration(row, healthy)
    started = time.perf_counter()
    log = field_sim.simulate(
        drive, H, length, speed_loop=loop(chain, operation), seed=1,
        drift=wear(row, drive, operation), drift_interval=1.0,
    )  # fmt: skip
    simulated = time.perf_counter() - started
    J, k, B = CHAINS[chain]
    n = len(J)
    given = {f"J[{i + 1}]": J[i] for i in range(n)}
    given.update({f"k[{i + 1}]": k[i] for i in range(n)})
    given.update({f"B[{i + 1}]": B[i] for i in range(n)})
    given.update({"D_m": defaults.D_M, "f_c": defaults.F_C, "mode": 2})
    columns = {"time": log.time, "i_a": log.i_a, "omega_m": log.omega_m, "theta_m": log.theta_m}
    drive_log = DriveLog(Path(f"{chain}-{operation}-{row}.csv"), columns)
    started = time.perf_counter()
    with FmuInstance(folder(n) / f"{OBSERVER.name}.fmu", "observer") as observer:
        tracked = replay_tracking(observer, drive_log, given, n)
    replayed = time.perf_counter() - started
    return {
        "chain": chain,
        "operation": operation,
        "row": row,
        "seconds": length,
        "simulate_s": round(simulated, 1),
        "replay_s": round(replayed, 1),
        **score(row, tracked, wear(row, drive, operation)(length)),
    }


def score(row: str, tracked: TrackedChain, truth: field_sim.Drive) -> dict:
    """A row's figures from its tracked replay and the drive at its end."""
    t = tracked.time
    later = t >= WARM_UP
    rising = np.flatnonzero(np.diff(tracked.alarm) > 0) + 1
    n = len(truth.k)
    k_error = tracked.values[:, :n] / np.array(truth.k) - 1.0
    out = {
        "k1_end": float(tracked.values[-1, 0]),
        "k1_true": truth.k[0],
        "k1_error_end": float(k_error[-1, 0]),
        "k_error_end_max": float(np.max(np.abs(k_error[-1]))),
        "k1_std_end": float(tracked.stds[-1, 0]),
        "f_c_end": float(tracked.values[-1, 2 * n]),
        "f_c_true": truth.f_c,
        "f_c_error_end": float(tracked.values[-1, 2 * n] / truth.f_c - 1.0),
        "alarm_end": int(tracked.alarm[-1]),
        "valid_share": float(np.mean(tracked.valid[later] > 0)),
        "alarms_after_warm_up": int(np.sum(t[rising] >= WARM_UP)) + int(tracked.alarm[later][0]),
        "k_error_max_after_warm_up": float(np.max(np.abs(k_error[later]))),
        "k_spread_after_warm_up": float(np.max(np.std(k_error[later], axis=0))),
    }
    if row in ("k", "friction"):
        first = tracked.first_alarm()
        out["alarm_after_drift_start_s"] = None if first is None else first - DRIFT_START
        out["alarms_before_drift"] = int(np.sum(t[rising] < DRIFT_START))
    return out


def cost(folder: Callable[[int], Path], steps: int = 2000) -> list[dict]:
    """µs per observer FMU step through fmpy, tracking off (estimator 1) and on."""
    rows = []
    for n in (2, 3, 5):
        row = {"n": n}
        for label, parameters in (("off", {"estimator": 1}), ("on", {"tracking": 1})):
            with FmuInstance(folder(n) / f"{OBSERVER.name}.fmu", "cost") as fmu:
                fmu.initialize({"mode": 2, **parameters})
                t = np.arange(steps + 1) * H
                theta = 0.5 * (1 - np.cos(3.0 * t))
                current = 0.3 * np.sin(3.0 * t)
                write = fmu.real_writer(["i_a", "omega_m", "theta_m"])
                started = time.perf_counter()
                for k in range(1, steps + 1):
                    write(
                        [float(current[k]), float((theta[k] - theta[k - 1]) / H), float(theta[k])]
                    )
                    fmu.do_step(float(t[k - 1]), H)
                row[f"us_per_step_{label}"] = round((time.perf_counter() - started) / steps * 1e6)
        rows.append(row)
    return rows


def table(results: list[dict]) -> str:
    """The runs as a Markdown table."""
    head = (
        "| chain | operation | row | k_1 end (truth) | k error end, worst | f_c end (truth) "
        "| alarm at end | alarm after drift start | alarms after 60 s | valid share |\n"
        "|---|---|---|---|---|---|---|---|---|---|"
    )
    lines = [head]
    for r in results:
        after = r.get("alarm_after_drift_start_s")
        lines.append(
            f"| {r['chain']} | {r['operation']} | {r['row']} "
            f"| {r['k1_end']:.4f} ({r['k1_true']:.4f}) | {100 * r['k_error_end_max']:.1f} % "
            f"| {1e3 * r['f_c_end']:.3f} ({1e3 * r['f_c_true']:.3f}) mN·m "
            f"| {r['alarm_end']} | {'—' if after is None else f'{after:.0f} s'} "
            f"| {r['alarms_after_warm_up'] if r['row'] in ('healthy', 'constant') else '—'} "
            f"| {100 * r['valid_share']:.0f} % |"
        )
    return "\n".join(lines)


def cost_table(rows: list[dict]) -> str:
    """The per-step cost as a Markdown table."""
    lines = ["| n | µs/step, tracking off (estimator 1) | µs/step, tracking on |", "|---|---|---|"]
    lines += [f"| {r['n']} | {r['us_per_step_off']} | {r['us_per_step_on']} |" for r in rows]
    return "\n".join(lines)


ROWS = ("k", "friction", "healthy", "constant")
OPERATIONS = ("position", "speed", "conveyor")


def _execute(args: argparse.Namespace) -> int:
    from arcosim import ensure_built

    def folder(n: int) -> Path:
        return ensure_built(n)

    results = []
    for chain in args.chains:
        for row in args.rows:
            for operation in ["conveyor"] if row == "constant" else args.operations:
                progress(f"{chain}, {operation}, {row}")
                results.append(run(chain, operation, row, args.healthy, folder))
    if results:
        print(table(results))
    costs = cost(folder) if args.cost else []
    if costs:
        print(cost_table(costs))
    if args.out:
        args.out.write_text(json.dumps({"runs": results, "cost": costs}, indent=2))
    return 0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the benchmark ``tracking``."""
    p = subparsers.add_parser(
        "tracking",
        help="the observer FMU's tracker on drives that wear while they work",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--chains", nargs="+", choices=list(CHAINS), default=list(CHAINS))
    p.add_argument("--operations", nargs="+", choices=OPERATIONS, default=["position"],
                   help="operations for the k, friction and healthy rows (default position; "
                   "the constant row always runs the conveyor)")  # fmt: skip
    p.add_argument("--rows", nargs="*", choices=ROWS, default=list(ROWS),
                   help="rows to run (default all; none with --cost: the cost alone)")  # fmt: skip
    p.add_argument("--healthy", type=float, default=HEALTHY,
                   help=f"a healthy run's length (s, default {HEALTHY:g})")  # fmt: skip
    p.add_argument("--cost", action="store_true", help="also the per-step cost, n = 2, 3, 5")
    p.add_argument("--out", type=Path, help="also write every run as JSON")
    p.set_defaults(execute=_execute)


if __name__ == "__main__":
    import sys

    from benchmarks import main

    sys.exit(main("tracking", add_parser, sys.argv[1:]))
