"""How far the estimator bank can reach (``python -m benchmarks.bank_reach``).

``arcosim bench control`` finds the four-mass chain's sensorless moves slower than 1.3 ×
their upper bound under model errors. This asks why, on one of its chains: per seed and
model (the identified chain, the seed's random errors and, on the first seed, the two
corners), a 1 rad move of the last mass by

- the controller as shipped (the bank chooses its member during the move),
- the controller with each of the bank's members given from the start and kept (9 runs):
  the best of them is what any choice among the members could reach,
- the controller as shipped with the load-torque estimate d̂ not fed back (the feedback's
  offset and holding current at d̂ = 0, as in the upper bound): what d̂'s error during
  the settling costs (d̂ is what holds a load; this is a diagnosis, not a design),
- the full-state upper bound (same design).

Every time is the ±1 % settling of the last mass (s). Prints a table and counts how many
cases each run settles within 1.3 × the bound; writes ``bank_reach.md`` into ``--out``.
About 10 s per case on a 2-core machine (each case 12 runs of 6 s).

Examples
--------
``python -m benchmarks.bank_reach --chain 2 --seeds 0 3 9``
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from arcosim import MotionController, ensure_built
from arcosim.experiments import (
    UPPER_BOUND_FACTOR,
    Runs,
    design_parameters,
    identify_chain,
    markdown_table,
    scaled,
    sensorless,
)
from arcosim.fmu.flexchain import EstimatorBank
from benchmarks.control_accuracy import CHAINS, score, seed_models


class WithoutLoadTorque(MotionController):
    """The controller with the load-torque estimate left out of the feedback (d̂ = 0)."""

    def _command(self, h: float, theta_ref: float, x: list[float], d: float) -> float:
        return super()._command(h, theta_ref, x, 0.0)


def fixed(params: dict[str, float], member: int) -> MotionController:
    """The controller on ``params`` with the bank's member ``member`` taken throughout,
    as it is (not refined from the move)."""
    controller = sensorless(params)
    bank = controller.bank
    bank.pick = member

    def step(h: float, tau_reac_hat: float, theta_m: float, *_: object) -> None:
        EstimatorBank.step(bank, h, tau_reac_hat, theta_m, False)

    def restart() -> None:
        EstimatorBank.restart(bank)
        bank.record = None  # nor refined from the move (move_fit)

    bank.step, bank.restart = step, restart
    return controller


def settling(runs: Runs, controller: object, full_state: bool = False) -> float:
    """The ±1 % settling time of the last mass (s) in one run."""
    return score(runs.run(controller, full_state=full_state)).settle_1


def reach(chain_index: int, seeds: Sequence[int]) -> list[dict[str, object]]:
    """One row per seed and model: the bound, the shipped controller, the best fixed
    member and the controller without d̂ (settling times, s)."""
    chain = list(CHAINS.values())[chain_index]
    folder = ensure_built(chain.n)
    rows = []
    for seed in seeds:
        params = design_parameters(identify_chain(folder, chain, False, seed), False)
        runs = Runs(folder, chain, False, seed=seed)
        for label, (fJ, fk) in seed_models(chain.n, seed, seed == seeds[0]).items():
            wrong = scaled(params, fJ, fk)
            shipped = sensorless(wrong)
            row: dict[str, object] = {"seed": seed, "model": label}
            row["bound"] = settling(runs, sensorless(wrong), full_state=True)
            row["shipped"] = settling(runs, shipped)
            row["chosen"] = shipped.bank.factors[shipped.bank.pick]
            times = [settling(runs, fixed(wrong, j)) for j in range(len(shipped.bank.members))]
            best = int(np.argmin(times))
            row["best"], row["best_member"] = times[best], shipped.bank.factors[best]
            without = WithoutLoadTorque(shipped.design)
            row["without_d"] = settling(runs, without)
            rows.append(row)
            print(f"  … seed {seed}, {label}: {_line(row)}", flush=True)
    return rows


def _line(row: dict[str, object]) -> str:
    """The row's times in one line."""
    return (
        f"bound {row['bound']:.2f} s, shipped {row['shipped']:.2f}, best member "
        f"{row['best']:.2f} {row['best_member']}, without d̂ {row['without_d']:.2f}"
    )


def markdown(rows: list[dict[str, object]]) -> str:
    """The table and the counts within UPPER_BOUND_FACTOR × the bound."""
    header = [
        "seed",
        "model",
        "bound (s)",
        "as shipped (s)",
        "member chosen (J, k factors)",
        "best fixed member (s)",
        "that member",
        "without d̂ (s)",
    ]
    body = [
        [
            str(r["seed"]),
            str(r["model"]),
            f"{r['bound']:.2f}",
            f"{r['shipped']:.2f}",
            str(r["chosen"]),
            f"{r['best']:.2f}",
            str(r["best_member"]),
            f"{r['without_d']:.2f}",
        ]
        for r in rows
    ]

    def within(key: str) -> int:
        return sum(float(r[key]) <= UPPER_BOUND_FACTOR * float(r["bound"]) for r in rows)

    counts = (
        f"Within {UPPER_BOUND_FACTOR:g} × the bound, of {len(rows)}: as shipped "
        f"{within('shipped')}, the best fixed member {within('best')}, without d̂ "
        f"{within('without_d')}."
    )
    return markdown_table(header, body) + "\n\n" + counts + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """Run the diagnosis; print and write the table."""
    p = argparse.ArgumentParser(prog="python -m benchmarks.bank_reach", description=__doc__)
    p.add_argument(
        "--chain",
        type=int,
        default=2,
        choices=range(len(CHAINS)),
        help="which chain of `arcosim bench control` (0, 1, 2; default 2, the four-mass one)",
    )
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2], help="plant seeds")
    p.add_argument("--out", type=Path, default=Path("reports"), help="folder for the table")
    args = p.parse_args(argv)
    started = time.perf_counter()
    print(f"{list(CHAINS)[args.chain]}, seeds {args.seeds}", flush=True)
    text = markdown(reach(args.chain, args.seeds))
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "bank_reach.md").write_text(text, encoding="utf-8")
    print(f"{time.perf_counter() - started:.0f} s; wrote {args.out / 'bank_reach.md'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
