"""One-off measurement: the noise levels the model-based observer's Kalman design solves.

Behind ``NOISE_RANGE`` and ``NOISE_RATIO`` of :mod:`arcosim.fmu.flexchain.model_observer`
(LOW, HIGH and RATIO when no arguments are given): designs the steady-state gain
(:func:`arcosim.fmu.flexchain.model_observer.step_model`) for torque_noise_std and
tau_noise_std at the corners and inside of the envelope (both in [LOW, HIGH] N.m,
neither more than RATIO times the other), over n = 1, 3, 8 masses (bench chains),
encoders of 0, 64, 2000 and 2^20 counts, steps 1e-5 … 1e-2 s and g_dist 10, 100,
1000 rad/s, and prints how many fail.

    python -m benchmarks.noise_envelope                 # 3312 designs, 0 failed (~3 min)
    python -m benchmarks.noise_envelope 1e-9 1e6 1e15   # fails where one is 1e10 x the other
"""

from __future__ import annotations

import itertools
import math
import sys
import time

from arcosim.fmu.flexchain import NOISE_RANGE, NOISE_RATIO, NoiseModel, defaults, step_model


def envelope_pairs(low: float, high: float, ratio: float) -> list[tuple[float, float]]:
    """(torque, tau) pairs: grid levels inside the envelope, and its ratio edges."""
    levels = sorted({low, 1e-6, 1e-3, 1.0, high})
    pairs = {(a, b) for a in levels for b in levels}
    pairs |= {(min(high, a * ratio), a) for a in levels} | {
        (a, min(high, a * ratio)) for a in levels
    }

    def inside(a: float, b: float) -> bool:
        return low <= a <= high and low <= b <= high and max(a / b, b / a) <= ratio * 1.000001

    return sorted(p for p in pairs if inside(*p))


def main(argv: list[str]) -> int:
    low, high, ratio = (float(x) for x in argv[:3])
    failed, count, start = [], 0, time.perf_counter()
    for n in (1, 3, 8):
        J, k, B = defaults.inertias(n), [defaults.K] * n, [defaults.B] * n
        for cpr, (torque, tau) in itertools.product(
            (0, 64, 2000, 1 << 20), envelope_pairs(low, high, ratio)
        ):
            theta = 0.0 if cpr == 0 else 2 * math.pi / cpr / math.sqrt(12)
            for h, g in itertools.product((1e-5, 1e-4, 1e-3, 1e-2), (10.0, 100.0, 1000.0)):
                count += 1
                try:
                    gain = step_model(J, k, B, g, NoiseModel(theta, torque, tau), h).K
                    ok = all(math.isfinite(x) for x in gain)
                except (ValueError, ZeroDivisionError, OverflowError) as error:
                    ok, why = False, str(error)
                else:
                    why = "a non-finite gain"
                if not ok:
                    failed.append((n, cpr, torque, tau, h, g, why))
    elapsed = time.perf_counter() - start
    print(f"[{low:g}, {high:g}] N.m, ratio <= {ratio:g}: {count} designs, {len(failed)} failed")
    print(f"({elapsed:.0f} s)")
    for row in failed[:20]:
        n, cpr, torque, tau, h, g, why = row
        print(f"  n={n} cpr={cpr} torque={torque:g} tau={tau:g} h={h:g} g_dist={g:g}: {why}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:] or [repr(x) for x in (*NOISE_RANGE, NOISE_RATIO)]))
