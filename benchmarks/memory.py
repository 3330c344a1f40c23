"""Resident memory of a long observer run: does anything grow with the record length?

    python benchmarks/memory.py [--steps 1000000] [--mode 1] [--masses 3]

Drives the observer FMU (through fmpy's FMI calls, one set and one get per step)
with a synthetic motor signal, samples the process's resident memory (VmRSS) every
tenth of the run, and reports the growth after the first tenth, plus whether the
FMU's log stayed silent. Exit status 1 if the log was not silent.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

from arcosim import FmuInstance, ensure_built
from arcosim.build import OBSERVER


def rss_mib() -> float:
    """Resident set size of this process (MiB), from /proc."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1_000_000)
    parser.add_argument("--mode", type=int, default=1, choices=(0, 1, 2))
    parser.add_argument("--masses", type=int, default=3)
    args = parser.parse_args()
    fmu = ensure_built(args.masses) / f"{OBSERVER.name}.fmu"
    h = 1e-3
    samples = []
    with FmuInstance(fmu, "memory") as observer:
        write = observer.real_writer(["i_a", "omega_m", "theta_m"])
        read = observer.reader(["tau_reac_hat", "k_hat", "theta_hat[1]"])
        observer.initialize({"mode": args.mode, "f_c": 2e-3})
        start = time.perf_counter()
        tenth = max(1, args.steps // 10)
        for k in range(args.steps):
            t = k * h
            write([0.3 * math.sin(5 * t), 4 * math.cos(5 * t), 0.8 * math.sin(5 * t)])
            if observer.do_step(t, h) != 0:
                print(f"step {k} refused: {observer.messages[-1:]}")
                return 1
            read()
            if (k + 1) % tenth == 0:
                samples.append((k + 1, rss_mib()))
        elapsed = time.perf_counter() - start
        messages = list(observer.messages)
    print(
        f"observer FMU, mode {args.mode}, n = {args.masses}: {args.steps} steps in {elapsed:.1f} s "
        f"({1e6 * elapsed / args.steps:.1f} µs per step with set/get)"
    )
    print("   steps   RSS (MiB)")
    for k, rss in samples:
        print(f"{k:8d}   {rss:9.1f}")
    if len(samples) > 1:
        print(f"growth after the first tenth: {samples[-1][1] - samples[0][1]:+.2f} MiB")
    print(f"log lines: {len(messages)}" + (f" (first: {messages[0]})" if messages else " (silent)"))
    return 1 if messages else 0


if __name__ == "__main__":
    sys.exit(main())
