"""Sensorless motion control against its four Done-when criteria (``arcosim bench control``).

Three chains of our own whose lowest mode is at least 10 rad/s (none of them the bench
or the five-mass chain of ``arcosim reproduce``), realistic sensors (2000-count encoder,
5 mA current noise), one plant noise seed per run. Per seed: the chain identified by
``identify_drive`` from a 20 s log of the plant (the ``identification`` multi-sine), then
a 1 rad move of the last mass in 6 s by the drive's cascade (the residual's reference)
and by the sensorless controller and its full-state upper bound, each designed on

- the identified chain,
- the identified chain with every J_i and k_i scaled by independent uniform factors in
  [0.9, 1.1] (numpy's generator seeded with the seed),
- on the first seed only (they are deterministic, and the identified chains of the seeds
  differ by about 0.1 %), the two corners: all J +10 % with all k −10 %, and the reverse.

A seed passes a criterion when the sensorless move settles the last mass within ±1 % in
≤ 2.5 s, leaves a residual ≤ max(0.1 × the cascade's, 1 mrad rms), settles within 1.3 ×
the upper bound's time (same design) and holds no motor limit cycle over one count
(:func:`arcosim.experiments.motion.findings.done_when`). Prints the pass counts per chain
and model; writes ``control.md`` and ``control.json`` into ``--out``.

``--encoder-cpr`` sets the encoder of the plant, of the identification's log and of the
controller's design alike (default 2000); the limit cycle is counted in its counts.

``--target-offset`` moves the target that many counts of that encoder past 1 rad
(default 0). Where the target falls within a count decides much of the hold: the plant's
encoder counts from the start, so 1 rad lies 318.31 counts on at 2000 counts, and the
motor holds the last mass there with its dither across the nearer edge; an offset of
−0.31 puts the target on an edge, +0.19 half way between two (docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from arcosim import Chain, UserError, ensure_built
from arcosim.experiments import (
    DISTANCE,
    I_MAX,
    MOVE_TIME,
    CascadeController,
    LoopRun,
    MoveScore,
    Runs,
    cascade_gains,
    chain_modes,
    design_parameters,
    done_when,
    identify_chain,
    markdown_table,
    model_errors,
    scaled,
    score_move,
    sensorless,
)
from arcosim.fmu.flexchain import ENCODER_CPR, PARTS, defaults
from arcosim.host import INT_MAX
from benchmarks import progress

#: The chains: lowest modes 19.7, 17.1 and 13.4 rad/s (motor free), damped at 0.05–0.2 %.
#: By their names in tables (kg·m², N·m/rad, N·m·s/rad).
CHAINS = {
    "two-mass, heavy tip": Chain(J=(5e-4, 1.5e-3), k=(0.3, 0.15), B=(1e-5, 1e-5)),
    "three-mass, soft middle": Chain(J=(4e-4, 3e-4, 8e-4), k=(0.3, 0.12, 0.25), B=(1e-5,) * 3),
    "four-mass, soft": Chain(J=(3e-4, 4e-4, 3e-4, 5e-4), k=(0.15, 0.12, 0.15, 0.1), B=(1e-5,) * 4),
}
#: The models per seed, in the table's order.
MODELS = ("identified", "random errors", "J +10 %, k −10 %", "J −10 %, k +10 %")
CRITERIA = ("settles", "residual", "near_bound", "no_limit_cycle")


def score_seed(
    chain: Chain,
    folder: Path,
    seed: int,
    corners: bool,
    encoder_cpr: int = ENCODER_CPR,
    distance: float = DISTANCE,
    without: frozenset[str] = frozenset(),
) -> dict[str, dict]:
    """One seed on one chain: every model's sensorless and upper-bound moves, and the
    criteria; the corners only when ``corners``; an encoder of ``encoder_cpr`` counts; a
    move of ``distance`` (rad); the controller's parts in ``without`` switched off."""
    result = identify_chain(folder, chain, False, seed, encoder_cpr)
    params = design_parameters(result, False, encoder_cpr)
    runs = Runs(folder, chain, False, seed=seed, encoder_cpr=encoder_cpr, distance=distance)

    def _score(run) -> MoveScore:
        return score(run, encoder_cpr, distance)

    cascade = _score(runs.run(CascadeController(cascade_gains(params), MOVE_TIME, I_MAX)))
    out = {}
    for label, (fJ, fk) in seed_models(chain.n, seed, corners).items():
        wrong = scaled(params, fJ, fk)
        moving = _score(runs.run(sensorless(wrong, without=without)))
        upper = _score(runs.run(sensorless(wrong, without=without), full_state=True))
        out[label] = {
            "sensorless": moving.as_dict(),
            "upper_bound": upper.as_dict(),
            "cascade": cascade.as_dict(),
            "criteria": done_when(moving, cascade, upper),
        }
    return out


def seed_models(n: int, seed: int, corners: bool) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The models one seed is designed on, by :data:`MODELS` name: the factors on every J_i
    and k_i (dimensionless, shape ``(n,)`` each) of the identified chain, the seed's random
    errors and, when ``corners``, the two corners.

    Examples
    --------
    >>> list(seed_models(2, 1, corners=False))
    ['identified', 'random errors']
    """
    errors = model_errors(n, (seed,))
    models = {"identified": (np.ones(n), np.ones(n))}
    models.update(list(zip(MODELS[1:], errors.values()))[: 3 if corners else 1])
    return models


def score(run: LoopRun, encoder_cpr: int = ENCODER_CPR, distance: float = DISTANCE) -> MoveScore:
    """A move's scores (``distance`` in rad, 1 by default), the limit cycle in counts of an
    ``encoder_cpr`` encoder."""
    return score_move(run, distance, distance, encoder_cpr)


def target_distance(offset: float, encoder_cpr: int) -> float:
    """The move (rad) whose target lies ``offset`` counts of an ``encoder_cpr`` encoder
    past 1 rad.

    Examples
    --------
    >>> round(target_distance(0.19, 2000) * 2000 / (2 * math.pi), 2)  # counts from the start
    318.5
    """
    return DISTANCE + offset * 2.0 * math.pi / encoder_cpr


def geometry(distance: float, encoder_cpr: int) -> str:
    """Where the target lies in the plant's counts, for the report.

    Examples
    --------
    >>> geometry(1.0, 2000)
    'Move: 1 rad, 318.31 counts of the encoder from the start (0.31 count from the nearer edge).'
    """
    counts = distance * encoder_cpr / (2.0 * math.pi)
    off = abs(counts - round(counts))
    return (
        f"Move: {distance:.9g} rad, {counts:.2f} counts of the encoder from the start "
        f"({off:.2f} count from the nearer edge)."
    )


def run(
    out: Path,
    seeds: Sequence[int],
    chains: Mapping[str, Chain],
    progress: Callable[[str], None],
    encoder_cpr: int = ENCODER_CPR,
    distance: float = DISTANCE,
    without: frozenset[str] = frozenset(),
    stop_on_failure: bool = False,
) -> dict[str, object]:
    """Every chain over ``seeds`` with an encoder of ``encoder_cpr`` counts and a move of
    ``distance`` (rad), the controller's parts in ``without`` switched off; with
    ``stop_on_failure``, up to the first seed where a run misses a criterion; the table, the
    per-seed results, the time (s)."""
    started = time.perf_counter()
    results: dict[str, dict] = {}
    for name, chain in chains.items():
        folder = ensure_built(chain.n)
        modes = chain_modes({"J_mo": defaults.J_M, **chain.parameters()})[0]
        per_seed = {}
        for seed in seeds:
            progress(f"{name}: seed {seed}")
            per_seed[str(seed)] = found = score_seed(
                chain, folder, seed, seed == seeds[0], encoder_cpr, distance, without
            )
            failed = not all(all(m["criteria"].values()) for m in found.values())
            if stop_on_failure and failed:
                break
        results[name] = {"lowest_mode": float(modes[0]), "seeds": per_seed}
        if stop_on_failure and failed:
            break
    heading = f"Encoder: {encoder_cpr} counts per revolution. {geometry(distance, encoder_cpr)}"
    if without:
        heading += f" Controller without: {', '.join(sorted(without))}."
    text = heading + "\n\n" + markdown(results)
    summary = {
        "without": sorted(without),
        "encoder_cpr": encoder_cpr,
        "distance": distance,
        "results": results,
        "seconds": time.perf_counter() - started,
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / "control.md").write_text(text, encoding="utf-8")
    (out / "control.json").write_text(json.dumps(summary, indent=1, default=str), "utf-8")
    return {"table": text, **summary}


HEADER = [
    "chain (lowest mode)",
    "model",
    "settles ≤ 2.5 s",
    "residual",
    "≤ 1.3 × bound",
    "limit cycle ≤ 1",
    "all four",
    "±1 % settling: median, worst (s)",
    "bound's median (s)",
    "worst residual (mrad)",
    "worst limit cycle (counts)",
]


def markdown(results: dict[str, dict]) -> str:
    """Pass counts (of the seeds run) per chain and model, and the spread of settling."""
    rows = []
    for chain, found in results.items():
        for model in MODELS:
            seeds = [s[model] for s in found["seeds"].values() if model in s]
            count = len(seeds)
            passed = [sum(bool(s["criteria"][c]) for s in seeds) for c in CRITERIA]
            every = sum(all(s["criteria"].values()) for s in seeds)
            settle = [s["sensorless"]["settle_1"] for s in seeds]
            bound = [s["upper_bound"]["settle_1"] for s in seeds]
            residual = max(s["sensorless"]["residual"] for s in seeds)
            cycle = max(s["sensorless"]["limit_cycle"] for s in seeds)
            rows.append(
                [
                    f"{chain} ({found['lowest_mode']:.1f} rad/s)",
                    model,
                    *(f"{p}/{count}" for p in passed),
                    f"{every}/{count}",
                    f"{_s(float(np.median(settle)))}, {_s(max(settle))}",
                    _s(float(np.median(bound))),
                    f"{1e3 * residual:.2f}",
                    f"{cycle:g}",
                ]
            )
    return markdown_table(HEADER, rows) + "\n"


def _s(value: float) -> str:
    return "never" if math.isinf(value) else f"{value:.2f}"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim bench control``."""
    p = subparsers.add_parser(
        "control",
        help="sensorless motion control: Done-when pass counts over seeds",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--seeds", type=int, default=20, help="plant seeds per chain (default 20)")
    p.add_argument("--quick", action="store_true", help="the first chain only")
    p.add_argument("--out", type=Path, default=Path("reports"), help="folder for the table")
    p.add_argument(
        "--encoder-cpr",
        type=int,
        default=ENCODER_CPR,
        metavar="N",
        help=f"the encoder's counts per revolution, of the plant, the identification's log "
        f"and the controller's design (default {ENCODER_CPR})",
    )
    p.add_argument(
        "--target-offset",
        type=float,
        default=0.0,
        metavar="COUNTS",
        help="the target this many encoder counts past 1 rad, −1 … 1 (default 0: 1 rad, "
        "0.31 count past an edge at 2000 counts)",
    )
    add_without(p)
    p.add_argument(
        "--stop-on-failure",
        action="store_true",
        help="stop after the first seed where a run misses a criterion (a screen)",
    )
    p.set_defaults(execute=_execute)


def add_without(p: argparse.ArgumentParser) -> None:
    """The ``--without PART[,PART…]`` option: the controller's parts switched off."""
    p.add_argument(
        "--without",
        type=parse_without,
        default=frozenset(),
        metavar="PART[,PART…]",
        help="switch these parts of the controller off, to measure what each buys "
        f"(default none; parts: {', '.join(PARTS)})",
    )


def parse_without(text: str) -> frozenset[str]:
    """The parts named in ``text`` (comma-separated), each one of the controller's ``PARTS``.

    Examples
    --------
    >>> sorted(parse_without("hold_gain,move_refit"))
    ['hold_gain', 'move_refit']
    """
    parts = frozenset(p.strip() for p in text.split(",") if p.strip())
    unknown = sorted(parts - set(PARTS))
    if unknown:
        raise UserError(
            f"--without names unknown parts {', '.join(unknown)}: use {', '.join(PARTS)}"
        )
    return parts


def _execute(args: argparse.Namespace) -> int:
    if args.seeds < 1:
        raise UserError(f"--seeds must be >= 1, got {args.seeds}")
    if not 1 <= args.encoder_cpr <= INT_MAX:  # the plant's encoder_cpr: an FMI Integer
        raise UserError(
            f"--encoder-cpr must be 1 … {INT_MAX} counts per revolution, got "
            f"{args.encoder_cpr} (an exact encoder is not benchmarked; default {ENCODER_CPR})"
        )
    if not -1.0 <= args.target_offset <= 1.0:  # NaN fails too
        raise UserError(
            f"--target-offset must be −1 … 1 counts past 1 rad, got {args.target_offset} "
            "(default 0)"
        )
    chains = dict(list(CHAINS.items())[:1]) if args.quick else CHAINS
    seeds = range(1, args.seeds + 1)
    distance = target_distance(args.target_offset, args.encoder_cpr)
    result = run(
        args.out, seeds, chains, progress, args.encoder_cpr, distance, args.without,
        args.stop_on_failure,
    )  # fmt: skip
    print(result["table"])
    print(f"wrote {args.out / 'control.md'} and {args.out / 'control.json'} "
          f"({result['seconds']:.0f} s)")  # fmt: skip
    return 0


if __name__ == "__main__":
    import sys

    from benchmarks import main

    sys.exit(main("control", add_parser, sys.argv[1:]))
