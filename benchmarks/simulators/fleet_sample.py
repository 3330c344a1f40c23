"""Write a simulated fleet for ``arcosim fleet``: the small fleet of the tests and the
guide, and the monitoring fleet of ``arcosim bench fleet``.

Every log comes from the independent simulator (:mod:`benchmarks.simulators.field_sim`), as
``arcosim bench verdict`` makes them: the paper bench's motor (J_m 2.09e-5 kg·m²,
k_t 0.0406 N·m/A, D_m 2e-5 N·m·s/rad, f_c 2e-3 N·m Coulomb friction that sticks) driving
a chain, 5 mA current noise, a 2000-count encoder, 1 ms, the ``identification``
scenario's 40 lines at 3 A; each log its own seed. The chains: n = 2, J = (4e-4, 8e-4)
kg·m² through k = (0.3, 0.2) N·m/rad, B = (2e-5, 1.5e-5) N·m·s/rad; n = 3, the paper
bench's chain. ``axis.toml`` gives k_to, J_mo, encoder_cpr only: the friction D_m, f_c
is fitted, and n chosen (``masses = "auto"``).

The small fleet (:func:`write_fleet`): axes of the two-mass drive, two dates each. On
the second date (2026-02-05) the first axis's k[1] is 12 % lower (a belt that lost
tension); every other axis is unchanged. The last axis also holds a corrupt log
(2026-01-20, a cell that is not a number), which the fleet records as failed.

The monitoring fleet (:func:`write_monitoring_fleet`, :data:`MONITORING`): 8 axes x 3
dates (2026-01-05, 02-05, 03-05), chains of n = 2 and n = 3, stick-slip friction three
times the bench's on two axes; on ``k-drop`` k[1] is 6 % then 12 % lower, on
``friction-rise`` f_c is 50 % then 100 % higher; ``corrupt`` also holds a corrupt log.
The expected alarms (latest against baseline): k[1] down on ``k-drop``, f_c up on
``friction-rise``, nothing elsewhere. ``seed`` draws every log's noise and phases.

Run: ``python -m benchmarks.simulators.fleet_sample DIR [--axes 3] [--seconds 20]`` or
``python -m benchmarks.simulators.fleet_sample DIR --monitoring [--seed 0]`` (from the repository
root; about 8 s of simulation per 20 s log), then ``arcosim fleet identify DIR --out
OUT`` and ``arcosim fleet drift OUT``.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

import arcosim
from arcosim.experiments import IDENTIFICATION_LINES
from arcosim.fmu.flexchain import defaults
from benchmarks.simulators import field_sim

#: The drive's first spring (N·m/rad), and the factor on it of the first axis's second date.
K1, DROP = 0.3, 0.88
#: The dates every axis of the small fleet has a log of.
DATES = ("2026-01-05", "2026-02-05")
#: The motor's Coulomb friction (N·m).
F_C = 2e-3
#: The chains by n: J (kg·m²), k (N·m/rad), B (N·m·s/rad).
CHAINS = {
    2: ((4e-4, 8e-4), (K1, 0.2), (2e-5, 1.5e-5)),
    3: (defaults.J, (defaults.K,) * 3, (defaults.B,) * 3),
}
#: A log that cannot be read (row 3's current is not a number).
CORRUPT = "time,i_a,omega_m,theta_m\n0,0,0,0\n0.001,x,0,0\n"


def write_axis_log(
    path: Path,
    n: int,
    seed: int,
    seconds: float = 20.0,
    *,
    k1_factor: float = 1.0,
    f_c: float = F_C,
) -> None:
    """One log of the chain of ``n`` masses, its k[1] times ``k1_factor``, the motor's
    Coulomb friction ``f_c`` (N·m), ``seconds`` long (s)."""
    J, k, B = CHAINS[n]
    drive = field_sim.Drive(
        J_m=defaults.J_M,
        k_t=defaults.K_T,
        J=J,
        k=(k[0] * k1_factor, *k[1:]),
        B=B,
        D_m=2e-5,
        f_c=f_c,
        current_noise=5e-3,
        counts=2000,
    )
    current = field_sim.multisine(IDENTIFICATION_LINES, 3.0, seed=seed + 1)
    log = field_sim.simulate(drive, 1e-3, seconds, current=current, seed=seed)
    columns = {"time": log.time, "i_a": log.i_a, "omega_m": log.omega_m, "theta_m": log.theta_m}
    arcosim.write_csv(path, columns)


def write_log(path: Path, k1: float, seed: int, seconds: float = 20.0) -> None:
    """One log of the two-mass drive with first spring ``k1`` (N·m/rad), ``seconds`` long (s)."""
    write_axis_log(path, 2, seed, seconds, k1_factor=k1 / K1)


def _axis_file(folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "axis.toml").write_text(
        f"[set]\nk_to = {defaults.K_T}\nJ_mo = {defaults.J_M}\nencoder_cpr = 2000\n",
        encoding="utf-8",
    )


def write_fleet(folder: Path, axes: int = 3, seconds: float = 20.0) -> list[str]:
    """Write the small fleet (the module's docstring) into ``folder``; the axes' names."""
    names = [f"a{i}" for i in range(1, axes + 1)]
    for a, name in enumerate(names):
        _axis_file(folder / name)
        for d, date in enumerate(DATES):
            k1 = K1 * (DROP if a == 0 and d == 1 else 1.0)
            write_log(folder / name / f"{date}.csv", k1, seed=10 * a + d, seconds=seconds)
    (folder / names[-1] / "2026-01-20.csv").write_text(CORRUPT, encoding="utf-8")
    return names


@dataclass(frozen=True)
class AxisPlan:
    """One axis of the monitoring fleet.

    Attributes
    ----------
    n : int
        Masses of its chain (2 or 3).
    f_c : float
        The motor's Coulomb friction on the first date (N·m).
    k1 : tuple of float
        k[1]'s factor on each date.
    friction : tuple of float
        f_c's factor on each date.
    corrupt : bool
        Whether the axis also holds a corrupt log.
    expect : tuple of (str, int)
        The alarms expected: parameter and sign of its change.
    """

    n: int
    f_c: float = F_C
    k1: tuple[float, ...] = (1.0, 1.0, 1.0)
    friction: tuple[float, ...] = (1.0, 1.0, 1.0)
    corrupt: bool = False
    expect: tuple[tuple[str, int], ...] = ()


#: The dates of the monitoring fleet.
MONITORING_DATES = ("2026-01-05", "2026-02-05", "2026-03-05")
#: The monitoring fleet by axis (stick-slip: f_c three times the bench's).
MONITORING = {
    "k-drop": AxisPlan(2, k1=(1.0, 0.94, 0.88), expect=(("k[1]", -1),)),
    "friction-rise": AxisPlan(2, friction=(1.0, 1.5, 2.0), expect=(("f_c", +1),)),
    "two": AxisPlan(2),
    "two-stick-slip": AxisPlan(2, f_c=3 * F_C),
    "corrupt": AxisPlan(2, corrupt=True),
    "three": AxisPlan(3),
    "three-stick-slip": AxisPlan(3, f_c=3 * F_C),
    "three-b": AxisPlan(3),
}


def write_monitoring_fleet(
    folder: Path, seed: int = 0, seconds: float = 20.0, progress=None
) -> dict[str, AxisPlan]:
    """Write the monitoring fleet (:data:`MONITORING`) into ``folder``, its noise drawn
    from ``seed``; the plan by axis. ``progress(text)`` is called before each log."""
    for a, (name, plan) in enumerate(MONITORING.items()):
        _axis_file(folder / name)
        for d, date in enumerate(MONITORING_DATES):
            if progress is not None:
                progress(f"simulating {name} {date}")
            write_axis_log(
                folder / name / f"{date}.csv",
                plan.n,
                seed=100_000 * seed + 10 * a + d,
                seconds=seconds,
                k1_factor=plan.k1[d],
                f_c=plan.f_c * plan.friction[d],
            )
        if plan.corrupt:
            (folder / name / "2026-01-20.csv").write_text(CORRUPT, encoding="utf-8")
    return dict(MONITORING)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--axes", type=int, default=3, help="axes of the small fleet")
    parser.add_argument("--seconds", type=float, default=20.0, help="each log's length (s)")
    parser.add_argument("--monitoring", action="store_true", help="the monitoring fleet")
    parser.add_argument("--seed", type=int, default=0, help="the monitoring fleet's noise")
    args = parser.parse_args()
    if args.monitoring:
        names = list(write_monitoring_fleet(args.folder, args.seed, args.seconds))
    else:
        names = write_fleet(args.folder, args.axes, args.seconds)
    print(f"wrote {len(names)} axes into {args.folder}")


if __name__ == "__main__":
    main()
