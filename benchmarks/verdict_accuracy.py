"""``arcosim bench verdict``: the whole-chain fit's verdict on logs with and without the
mistakes users make, over seeds.

Every log comes from the independent simulator (:mod:`benchmarks.simulators.field_sim`, written
apart from the plant FMU): a motor with Coulomb friction that sticks drives a chain,
a current sensor with 5 mA of noise, a 2000-count encoder, 1 ms, the ``identification``
scenario's 40 lines (3–150 rad/s, 3 A, 20 s; the seed draws the phases and the
noise). Each log is identified with :func:`arcosim.identify_drive` as a user would
(``masses="auto"``, the load left to the selection rule, the friction fitted).

Rows:

* **clean** (a two-mass and the paper's three-mass chain): expected ``trusted``, n right;
* **k_t ±10 %, J_m ±10 %, time in ms, current in A read as mA, the current's sign
  turned** (the two-mass chain): expected ``untrusted``, with a reason naming the
  cause's option (``k_to``/``J_mo``, ``--scale``; ``--scale i_a=-1`` for the sign);
* **a slow load torque** (5 % of the rated 3 A torque, constant plus a 0.7 rad/s sine,
  on the last mass) and **a 2¹⁷-count encoder with stick-slip friction three times the
  bench's**: expected n right, or ``untrusted``.

Per row: how often the verdict was trusted, how often n was right, how often the row's
expectation held, the reasons' first words, and the largest |error| of any J_i, k_i on
the trusted fits with n right.

Run: ``arcosim bench verdict [--seeds N] [--rows NAME ...] [--out FILE.json]`` (about
8 s a log on the 2-core machine; ``--seeds 20`` takes about 25 min).
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import arcosim
from arcosim import ArcosimError, UserError
from arcosim.experiments import IDENTIFICATION_LINES, markdown_table
from arcosim.fmu.flexchain import defaults
from benchmarks.simulators import field_sim

K_T, J_M, CPR = defaults.K_T, defaults.J_M, 2000
TWO = ((4e-4, 8e-4), (0.3, 0.2), (2e-5, 1.5e-5))
BENCH = (defaults.J, (defaults.K,) * 3, (defaults.B,) * 3)


@dataclass(frozen=True)
class Row:
    """One kind of log and what the verdict should say on it.

    Attributes
    ----------
    chain : tuple
        The true J_i (kg·m²), k_i (N·m/rad), B_i (N·m·s/rad).
    expect : str
        ``"trusted"`` (and n right), ``"untrusted"``, or ``"right or untrusted"``.
    given : dict
        What the user gives wrongly: ``k_t``, ``J_m`` factors, ``time``, ``i_a`` scales.
    drive : dict
        Changes to the simulated drive (friction, encoder, load torque).
    cause : str
        A word one of an untrusted fit's reasons must hold: the cause named (empty: not
        checked).
    """

    chain: tuple
    expect: str
    given: dict = field(default_factory=dict)
    drive: dict = field(default_factory=dict)
    cause: str = ""


RATED = 3.0 * K_T  # N·m
ROWS = {
    "clean, two masses": Row(TWO, "trusted"),
    "clean, the bench's three masses": Row(BENCH, "trusted"),
    "k_t given 10 % high": Row(TWO, "untrusted", {"k_t": 1.1}, cause="k_to"),
    "k_t given 10 % low": Row(TWO, "untrusted", {"k_t": 0.9}, cause="k_to"),
    "J_m given 10 % high": Row(TWO, "untrusted", {"J_m": 1.1}, cause="J_mo"),
    "J_m given 10 % low": Row(TWO, "untrusted", {"J_m": 0.9}, cause="J_mo"),
    "time in ms": Row(TWO, "untrusted", {"time": 1e3}, cause="--scale"),
    "current in A read as mA": Row(TWO, "untrusted", {"i_a": 1e-3}, cause="--scale"),
    "current's sign turned": Row(TWO, "untrusted", {"i_a": -1.0}, cause="--scale i_a=-1"),
    "slow load torque": Row(
        TWO,
        "right or untrusted",
        drive={"load_torque": 0.05 * RATED, "load_sine": (0.05 * RATED, 0.7)},
    ),
    "2^17-count encoder, stick-slip": Row(
        TWO, "right or untrusted", drive={"counts": 2**17, "f_c": 6e-3}
    ),
}


def simulate(row: Row, seed: int) -> field_sim.Log:
    """The row's log for ``seed`` (20 s at 1 ms)."""
    J, k, B = row.chain
    settings = {"D_m": 2e-5, "f_c": 2e-3, "current_noise": 5e-3, "counts": CPR, **row.drive}
    drive = field_sim.Drive(J_m=J_M, k_t=K_T, J=J, k=k, B=B, **settings)
    excitation = field_sim.multisine(IDENTIFICATION_LINES, 3.0, seed=seed + 1)
    return field_sim.simulate(drive, 1e-3, 20.0, current=excitation, seed=seed)


def score(row: Row, seed: int) -> dict:
    """Identify the row's log for ``seed`` as the user gives it; the verdict and errors."""
    log = simulate(row, seed)
    g = row.given
    ts, cs = g.get("time", 1.0), g.get("i_a", 1.0)
    started = time.perf_counter()
    try:
        result = arcosim.identify_drive(
            log.time * ts,
            log.i_a * cs,
            log.omega_m / ts,
            log.theta_m,
            k_t=K_T * g.get("k_t", 1.0),
            J_m=J_M * g.get("J_m", 1.0),
            encoder_cpr=int(row.drive.get("counts", CPR)),
        )
    except ArcosimError as error:
        return {"verdict": "refused", "n": None, "reasons": [str(error)], "seconds": 0.0}
    out = {
        "verdict": result.verdict.word,
        "n": result.masses,
        "reasons": list(result.verdict.reasons),
        "seconds": time.perf_counter() - started,
    }
    J, k, _ = row.chain
    if result.masses == len(J):
        p = result.parameters
        errors = [100 * (p[f"J[{i + 1}]"] / J[i] - 1) for i in range(len(J))]
        errors += [100 * (p[f"k[{i + 1}]"] / k[i] - 1) for i in range(len(J))]
        out["max_error_percent"] = float(np.max(np.abs(errors)))
    return out


def met(row: Row, run: dict) -> bool:
    """Whether ``run`` meets the row's expectation."""
    right = run["n"] == len(row.chain[0])
    untrusted = run["verdict"] in ("untrusted", "refused")
    named = any(row.cause in reason for reason in run["reasons"]) if row.cause else True
    if row.expect == "trusted":
        return run["verdict"] == "trusted" and right
    if row.expect == "untrusted":
        return untrusted and named
    return right or untrusted


def run(names: list[str], seeds: range, progress: Callable[[str], None]) -> dict:
    """Every row over ``seeds``: the runs and the table."""
    results = {}
    for name in names:
        runs = []
        for seed in seeds:
            progress(f"{name}: seed {seed}")
            runs.append(score(ROWS[name], seed))
        results[name] = runs
    return {"rows": results, "table": table(results)}


def table(results: dict[str, list[dict]]) -> str:
    """The markdown table of :func:`run`'s results."""
    head = ["log", "expected", "met", "trusted", "n right", "largest J_i, k_i error, trusted (%)"]
    rows = []
    for name, runs in results.items():
        row = ROWS[name]
        count = len(runs)
        trusted = [r for r in runs if r["verdict"] == "trusted"]
        errors = [r["max_error_percent"] for r in trusted if "max_error_percent" in r]
        rows.append(
            [
                name,
                row.expect,
                f"{sum(met(row, r) for r in runs)}/{count}",
                f"{len(trusted)}/{count}",
                f"{sum(r['n'] == len(row.chain[0]) for r in runs)}/{count}",
                f"{max(errors):.2f}" if errors else "—",
            ]
        )
    return markdown_table(head, rows)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the benchmark ``verdict``."""
    p = subparsers.add_parser(
        "verdict",
        help="the whole-chain fit's verdict on logs with and without users' mistakes",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--seeds", type=int, default=20, help="seeds per row (default 20)")
    p.add_argument("--rows", nargs="+", choices=list(ROWS), metavar="NAME",
                   help="only these rows (default: all)")  # fmt: skip
    p.add_argument("--out", type=Path, help="also write every run as JSON")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    if args.seeds < 1:
        raise UserError(f"--seeds must be >= 1, got {args.seeds}")
    result = run(args.rows or list(ROWS), range(args.seeds), progress)
    print(result["table"])
    if args.out:
        args.out.write_text(json.dumps(result["rows"], indent=1))
        print(f"wrote {args.out}")
    return 0


def progress(text: str) -> None:
    """One line on stderr per log."""
    import sys

    print(text, file=sys.stderr, flush=True)


if __name__ == "__main__":
    import sys

    from benchmarks import main

    sys.exit(main("verdict", add_parser, sys.argv[1:]))
