"""Write ``examples/data/belt_drive.csv``: the sample drive log the examples identify.

A belt drive the project was never tuned on, simulated by :mod:`benchmarks.simulators.field_sim`
(written apart from the plant): the paper bench's motor (J_m 2.09e-5 kg·m²,
k_t 0.0406 N·m/A, friction D_m 2e-5 N·m·s/rad and f_c 2e-3 N·m) turning a pulley of
3e-4 kg·m² and, through a belt, a load of 9e-4 kg·m² (springs 0.45 and 0.3 N·m/rad,
0.2 % damping), a 2000 rad/s current loop, 5 mA current noise, a 2000-count encoder,
1 kHz, 20 s of the multi-sine ``arcosim excite --band 3 150 --current-limit 3``
designs. Columns as a drive records them: ``time`` (s), ``i_a`` (mA), ``omega_m``
(counts/s, the encoder's backward difference), ``theta_m`` (counts), and the truth the
drive could not measure, ``theta_1_true``, ``theta_2_true`` (rad).

Run: ``python -m benchmarks.sample_log`` (from the repository root). The file itself is
``cosim/example-files/data/belt_drive.csv``, the package data ``arcosim example`` writes
out; ``examples/data/belt_drive.csv`` is a link to it.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from arcosim import design_excitation
from benchmarks.simulators import field_sim

ROOT = Path(__file__).resolve().parents[1]
#: The sample log: package data (``arcosim example``), linked from ``examples/data/``.
OUT = ROOT / "cosim" / "example-files" / "data" / "belt_drive.csv"
COUNTS = 2000
J, K = (3e-4, 9e-4), (0.45, 0.3)


def drive() -> field_sim.Drive:
    """The belt drive (truth)."""
    damping = [2 * 0.002 * np.sqrt(k * j) for k, j in zip(K, J)]
    return field_sim.Drive(
        J_m=2.09e-5,
        k_t=0.0406,
        J=J,
        k=K,
        B=tuple(damping),
        D_m=2e-5,
        f_c=2e-3,
        current_bandwidth=2000.0,
        current_noise=0.005,
        counts=COUNTS,
    )


def main(out: Path = OUT) -> None:
    """Simulate the belt drive and write its log to ``out`` (CSV, columns above)."""
    design = design_excitation((3.0, 150.0), 3.0)

    def current(t: np.ndarray) -> np.ndarray:
        return np.interp(t, design.time, design.signal)

    log = field_sim.simulate(drive(), 1e-3, 20.0, current=current, seed=7)
    count = 2 * np.pi / COUNTS
    counts = np.rint(log.theta_m / count).astype(np.int64)
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(["time", "i_a", "omega_m", "theta_m", "theta_1_true", "theta_2_true"])
        previous = counts[0]
        for k, t in enumerate(log.time):
            step = int(counts[k] - previous) * 1000 if k else 0
            previous = counts[k]
            writer.writerow(
                [
                    f"{t:.3f}",
                    f"{1e3 * log.i_a[k]:.2f}",
                    step,
                    int(counts[k]),
                    f"{log.theta_true[k, 1]:.7g}",
                    f"{log.theta_true[k, 2]:.7g}",
                ]
            )
    print(f"wrote {out} ({out.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
