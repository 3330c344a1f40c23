"""Write a simulated fleet for ``arcosim fleet``: axes of one two-mass drive, two dates each.

Every log comes from the independent simulator (:mod:`benchmarks.field_sim`), as
``arcosim bench verdict`` makes them: the paper bench's motor (J_m 2.09e-5 kg·m²,
k_t 0.0406 N·m/A, D_m 2e-5 N·m·s/rad, f_c 2e-3 N·m) driving J = (4e-4, 8e-4) kg·m²
through k = (0.3, 0.2) N·m/rad, B = (2e-5, 1.5e-5) N·m·s/rad; 5 mA current noise, a
2000-count encoder, 1 ms, the ``identification`` scenario's 40 lines at 3 A; each log
its own seed. On the second date (2026-02-05) the first axis's k[1] is 12 % lower (a
belt that lost tension); every other axis is unchanged. The last axis also holds a
corrupt log (2026-01-20, a cell that is not a number), which the fleet records as
failed.

Run: ``python -m benchmarks.fleet_sample DIR [--axes 3] [--seconds 20]`` (from the
repository root; about 8 s of simulation per 20 s log), then ``arcosim fleet identify
DIR --out OUT`` and ``arcosim fleet drift OUT``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import arcosim
from arcosim.experiments.scenarios import IDENTIFICATION_LINES
from arcosim.fmu.flexchain import defaults
from benchmarks import field_sim

#: The drive's first spring (N·m/rad), and the factor on it of the first axis's second date.
K1, DROP = 0.3, 0.88
#: The dates every axis has a log of.
DATES = ("2026-01-05", "2026-02-05")


def write_log(path: Path, k1: float, seed: int, seconds: float = 20.0) -> None:
    """One log of the drive with first spring ``k1`` (N·m/rad), ``seconds`` long (s)."""
    drive = field_sim.Drive(
        J_m=defaults.J_M,
        k_t=defaults.K_T,
        J=(4e-4, 8e-4),
        k=(k1, 0.2),
        B=(2e-5, 1.5e-5),
        D_m=2e-5,
        f_c=2e-3,
        current_noise=5e-3,
        counts=2000,
    )
    current = field_sim.multisine(IDENTIFICATION_LINES, 3.0, seed=seed + 1)
    log = field_sim.simulate(drive, 1e-3, seconds, current=current, seed=seed)
    columns = {"time": log.time, "i_a": log.i_a, "omega_m": log.omega_m, "theta_m": log.theta_m}
    arcosim.write_csv(path, columns)


def write_fleet(folder: Path, axes: int = 3, seconds: float = 20.0) -> list[str]:
    """Write the fleet (the module's docstring) into ``folder``; return the axes' names."""
    names = [f"a{i}" for i in range(1, axes + 1)]
    for a, name in enumerate(names):
        (folder / name).mkdir(parents=True, exist_ok=True)
        (folder / name / "axis.toml").write_text(
            f"[set]\nk_to = {defaults.K_T}\nJ_mo = {defaults.J_M}\nencoder_cpr = 2000\n",
            encoding="utf-8",
        )
        for d, date in enumerate(DATES):
            k1 = K1 * (DROP if a == 0 and d == 1 else 1.0)
            write_log(folder / name / f"{date}.csv", k1, seed=10 * a + d, seconds=seconds)
    corrupt = "time,i_a,omega_m,theta_m\n0,0,0,0\n0.001,x,0,0\n"
    (folder / names[-1] / "2026-01-20.csv").write_text(corrupt, encoding="utf-8")
    return names


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--axes", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=20.0)
    args = parser.parse_args()
    names = write_fleet(args.folder, args.axes, args.seconds)
    print(f"wrote {len(names)} axes into {args.folder}")


if __name__ == "__main__":
    main()
