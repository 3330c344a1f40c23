"""``arcosim bench accuracy``: every method on several chains, scored against the truth.

Cases (realistic sensors: 2000-count encoder, 5 mA current noise, 1 ms): the paper's
bench; a two-mass and a five-mass chain with other inertias and stiffnesses; and the
bench's masses on non-uniform springs (model mismatch: the methods assume one k).
Each case is co-simulated (plant FMU + observer FMU) with a rigid maneuver at an
eighth of its first mode and with a broadband multi-sine (3–150 rad/s, 1 A peak; the
bench also at the flexible scenario's 0.48 A, where its motor sticks a quarter of the
time), once per seed (seeds change the current noise). The observer's algorithms are
then run again on the recorded logs, offline, in every configuration (the same
``flexchain`` code the FMU bundles), so one pair of runs scores every method:

* identification: literal eq. 21 and eq. 21 with κ (rigid maneuver, mode 1) and
  output error (broadband, ``cosim/identification/fit/uniform_fit.py``); k̂ and B̂
  against the truth (the mean of the springs for the non-uniform case);
* state estimation on the broadband run: the paper's recursion (eq. 22–26), the
  model-based observer, and the naive ``θ̂_i = θ_m``; score per mass
  rms(θ̂_i − θ_i) / rms(θ_i − θ_m) (docs/method.md). The estimators use the output-error
  k̂, B̂ of the same run and the known J_i; the actuator terms are the plant's (what
  mode 0 returns to within 0.1 %).

The bench also gets the honesty check of B's standard error (over ``--b-seeds`` seeds)
and B on records of 2.5 … 20 s (3 seeds each): the record length B needs to come
within 10 %. Then the whole-chain identification rows (``benchmarks/chain_accuracy.py``:
three chains, the ``identification`` scenario, ``--b-seeds`` seeds; one in quick mode;
``--whole-chain-only`` runs them alone), each with the verdict's count (trusted k of N),
like the field and excitation rows after them.
Then the excitation rows (``benchmarks/excitation_accuracy.py``: an off-grid multi-sine,
a square-wave reference in a position loop, a PRBS; check agreeing with identify).
Last, the load torque rows (``benchmarks/load_accuracy.py``: the two- and five-mass chains,
the load on the last and on a middle mass, a model with springs 5 % off, the same
seeds; and the bandwidth's trade-off on the bench). Then the flexible-link rows
(``benchmarks/beam_accuracy.py``: three links, EI, ρA, the first two clamped modes and
the tip angle from the hub's current and encoder; ``--beam-only`` runs them alone).
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from arcosim import Scenario, UserError, motor_record, multisine, rigid_maneuver, uniform_chain
from arcosim.experiments import (
    BROADBAND_LINES,
    flexible_score,
    markdown_table,
    percent_error,
)
from arcosim.fmu.flexchain import Estimator, Mode, defaults
from arcosim.identification import MotorRecord, ParameterFit, estimate_states, replay
from benchmarks import (
    beam_accuracy,
    chain_accuracy,
    excitation_accuracy,
    field_accuracy,
    load_accuracy,
    progress,
)
from benchmarks.cases import ACTUATOR, CASES, G_DIST, Case, run_case, settings_for

#: Broadband lines (rad/s): the flexible scenario's plus 150 for the five-mass chain.
LINES = BROADBAND_LINES
BROADBAND_DURATION = 10.0
#: Peak current of the broadband multi-sine (A). At this level the bench's motor
#: stands still (|ω| < 0.5 rad/s) 2 % of the time; at the flexible scenario's 0.48 A,
#: 26 %, and Coulomb friction's sticking, seen through the 2000-count encoder, biases
#: B̂ by +56 % (rows "weak excitation").
BROADBAND_AMPLITUDE = 1.0
WEAK_AMPLITUDE = 0.48
#: Suffix of the method names scored on the weak excitation.
WEAK = f", weak excitation ({WEAK_AMPLITUDE:g} A)"
#: Record lengths (s) for the B-versus-record-length rows (bench).
RECORD_LENGTHS = (2.5, 5.0, 10.0, 20.0)


@dataclass
class CaseResult:
    """Per-seed numbers of one case (lists over seeds)."""

    k_error: dict[str, list[float]] = field(default_factory=dict)
    B_error: dict[str, list[float]] = field(default_factory=dict)
    state: dict[str, list[list[float]]] = field(default_factory=dict)

    def add(self, table: dict, method: str, value: object) -> None:
        table.setdefault(method, []).append(value)


def broadband(
    case: Case,
    seed: int,
    duration: float = BROADBAND_DURATION,
    amplitude: float = BROADBAND_AMPLITUDE,
) -> dict[str, np.ndarray]:
    """Co-simulate the broadband multi-sine (peak ``amplitude`` A); return the recorded
    signals by name."""
    scenario = Scenario(
        "broadband",
        "multi-sine 3–150 rad/s",
        lambda t: multisine(t, amplitude, LINES, 1),
        duration,
        {},
        {"mode": 2},
    )
    return run_case(case, scenario, seed)


def rigid(case: Case, seed: int) -> dict[str, np.ndarray]:
    """Co-simulate the rigid maneuver at an eighth of the first mode."""
    w = case.first_mode() / 8.0
    scenario = Scenario(
        "rigid",
        "rigid maneuver",
        lambda t: rigid_maneuver(t, frequency=w),
        8 * 2 * math.pi / w,
        {},
        {"mode": 1},
    )
    return run_case(case, scenario, seed)


def fit_broadband(case: Case, log: dict[str, np.ndarray]) -> tuple[MotorRecord, object]:
    record = motor_record(log["time"], log["i_a"], log["omega_m"], log["theta_m"], ACTUATOR, G_DIST)
    return record, uniform_chain(record, case.J)


@functools.cache
def broadband_fit(
    case: Case,
    seed: int,
    duration: float = BROADBAND_DURATION,
    amplitude: float = BROADBAND_AMPLITUDE,
) -> tuple[dict[str, np.ndarray], ParameterFit]:
    """:func:`broadband` and its uniform output-error fit, once per argument set: the
    table, B's check and the record lengths share the bench's runs (seeds 1 … 5 at
    10 s would otherwise be simulated and fitted up to three times). Read-only."""
    log = broadband(case, seed, duration, amplitude)
    return log, fit_broadband(case, log)[1]


def score_case(case: Case, seeds: Sequence[int], progress: Callable[[str], None]) -> CaseResult:
    """Every method on one case, over ``seeds``."""
    result = CaseResult()
    k_true, B_true = float(np.mean(case.k)), float(np.mean(case.B))
    for seed in seeds:
        progress(f"{case.name}: seed {seed}, rigid maneuver")
        log = rigid(case, seed)
        for method, kappa in (("eq. 21 (literal)", False), ("eq. 21 + kappa", True)):
            ident = replay(
                settings_for(case, Mode.RIGID_IDENTIFICATION, kappa_correction=kappa), log
            )
            ident.estimate()
            result.add(result.k_error, method, percent_error(ident.identifier.k, k_true))
            result.add(result.B_error, method, percent_error(ident.identifier.B, B_true))
        progress(f"{case.name}: seed {seed}, broadband")
        score_broadband(case, *broadband_fit(case, seed), result, "")
        if case is CASES[0]:
            progress(f"{case.name}: seed {seed}, weak broadband")
            weak = broadband_fit(case, seed, BROADBAND_DURATION, WEAK_AMPLITUDE)
            score_broadband(case, *weak, result, WEAK)
    return result


def score_broadband(
    case: Case, log: dict[str, np.ndarray], oe: ParameterFit, result: CaseResult, suffix: str
) -> None:
    """Output error (``oe``, fitted on ``log``), then the state estimators with its
    k̂, B̂, on one broadband log; method names get ``suffix``."""
    k_hat, B_hat = oe.values[0], oe.values[1]
    method = "output error" + suffix
    result.add(result.k_error, method, percent_error(k_hat, float(np.mean(case.k))))
    result.add(result.B_error, method, percent_error(B_hat, float(np.mean(case.B))))
    truth = [log[f"theta[{i}]"] for i in range(1, case.n + 1)]
    motor = log["theta_m_true"]
    identified = {"k": (k_hat,) * case.n, "B": (B_hat,) * case.n}
    for name, estimator in (
        ("recursion", Estimator.RECURSION),
        ("model-based", Estimator.MODEL_BASED),
    ):
        s = settings_for(case, Mode.STATE_ESTIMATION, estimator=estimator, **identified)
        est = estimate_states(s, log)
        scores = [flexible_score(est[:, i], truth[i], motor) for i in range(case.n)]
        result.add(result.state, name + suffix, scores)
    naive = [flexible_score(log["theta_m"], truth[i], motor) for i in range(case.n)]
    result.add(result.state, "naive theta_i = theta_m" + suffix, naive)


def b_honesty(seeds: Sequence[int], progress: Callable[[str], None]) -> dict[str, object]:
    """On the bench: how often |B̂ − B| ≤ 2σ over ``seeds``."""
    case = CASES[0]
    inside, sigmas, errors = 0, [], []
    for seed in seeds:
        progress(f"B's standard error: seed {seed}")
        _, oe = broadband_fit(case, seed)
        inside += abs(oe.values[1] - defaults.B) <= 2 * oe.std[1]
        sigmas.append(100 * oe.std[1] / defaults.B)
        errors.append(percent_error(oe.values[1], defaults.B))
    return {
        "seeds": len(seeds),
        "inside_2_sigma": int(inside),
        "B_error_percent": errors,
        "B_std_percent_median": float(np.median(sigmas)),
    }


def record_lengths(
    lengths: Sequence[float], seeds: Sequence[int], progress: Callable[[str], None]
) -> list[dict[str, object]]:
    """B̂'s error and standard error on the bench for records of each length (s)."""
    rows = []
    for duration in lengths:
        errors, sigmas = [], []
        for seed in seeds:
            progress(f"bench broadband record of {duration:g} s, seed {seed}")
            _, oe = broadband_fit(CASES[0], seed, duration)
            errors.append(percent_error(oe.values[1], defaults.B))
            sigmas.append(100 * oe.std[1] / defaults.B)
        rows.append({"duration_s": duration, "B_error_percent": errors, "B_std_percent": sigmas})
    return rows


def shortest_for_b(rows: Sequence[dict]) -> float | None:
    """The shortest record (s) whose every seed has B within 10 % and σ_B ≤ 5 %."""
    for row in rows:
        if max(abs(e) for e in row["B_error_percent"]) <= 10 and max(row["B_std_percent"]) <= 5:
            return float(row["duration_s"])
    return None


def markdown(results: dict[str, CaseResult], cases: Sequence[Case]) -> str:
    """The method × case table."""
    header = [
        "method",
        "case",
        "k error % (mean)",
        "k spread %",
        "B error % (mean)",
        "B spread %",
        "state error per mass (mean over seeds)",
    ]
    rows = []
    methods = [
        "eq. 21 (literal)",
        "eq. 21 + kappa",
        "output error",
        "recursion",
        "model-based",
        "naive theta_i = theta_m",
    ]
    methods += [m + WEAK for m in methods[2:]]
    for method in methods:
        for case in cases:
            r = results[case.name]
            if method not in r.k_error and method not in r.state:
                continue
            cells = [method, case.name]
            if method in r.k_error:
                k, b = np.array(r.k_error[method]), np.array(r.B_error[method])
                cells += [
                    f"{k.mean():+.3f}",
                    f"{k.std():.3f}",
                    f"{b.mean():+.1f}",
                    f"{b.std():.1f}",
                ]
            else:
                cells += ["", "", "", ""]
            if method in r.state:
                per_mass = np.mean(np.array(r.state[method]), axis=0)
                cells.append(" / ".join(_state_cell(x) for x in per_mass))
            else:
                cells.append("")
            rows.append(cells)
    return markdown_table(header, rows) + "\n"


def _state_cell(x: float) -> str:
    return f"{100 * x:.2f} %" if x < 10 else f"{x:.3g}×"


def run(
    out: Path,
    seeds: int,
    b_seeds: int,
    quick: bool,
    progress: Callable[[str], None] = print,
    load_torque_only: bool = False,
    beam_only: bool = False,
    whole_chain_only: bool = False,
) -> dict[str, object]:
    """Run the benchmark, write ``accuracy.md`` and ``accuracy.json`` into ``out``
    (``load_torque_only``: only the load torque rows, ``load_torque.md``/``.json``;
    ``beam_only``: only the flexible-link rows, ``beam.md``/``.json``;
    ``whole_chain_only``: only the whole-chain rows of the project's chains,
    ``whole_chain.md``/``.json``)."""
    started = time.perf_counter()
    for only, table, stem in (
        (load_torque_only, _load_torque_table, "load_torque"),
        (beam_only, _beam_table, "beam"),
        (whole_chain_only, _whole_chain_table, "whole_chain"),
    ):
        if only:
            return _rows_alone(out, max(b_seeds, seeds), quick, progress, started, table, stem)
    cases = CASES[:1] if quick else CASES
    seed_list = list(range(1, seeds + 1))
    results = {case.name: score_case(case, seed_list, progress) for case in cases}
    summary: dict[str, object] = {
        "cases": {
            c.name: {"J": c.J, "k": c.k, "B": c.B, "first_mode_rad_s": c.first_mode()}
            for c in cases
        },
        "seeds": seed_list,
        "results": {
            name: {"k_error": r.k_error, "B_error": r.B_error, "state": r.state}
            for name, r in results.items()
        },
    }
    text = markdown(results, cases)
    if b_seeds > 0:
        honesty = b_honesty(list(range(1, b_seeds + 1)), progress)
        summary["B_honesty"] = honesty
        text += (
            f"\nB's standard error (bench, {BROADBAND_DURATION:g} s records, "
            f"{honesty['seeds']} seeds): |B̂ − B| ≤ 2σ in {honesty['inside_2_sigma']}; "
            f"median σ_B {honesty['B_std_percent_median']:.1f} % of B.\n"
        )
    if not quick:
        rows = record_lengths(RECORD_LENGTHS, [1, 2, 3], progress)
        summary["record_lengths"] = rows
        text += "\n| record (s) | B error % per seed | σ_B % per seed |\n|---|---|---|\n"
        for row in rows:
            errs = " / ".join(f"{e:+.1f}" for e in row["B_error_percent"])
            sig = " / ".join(f"{x:.1f}" for x in row["B_std_percent"])
            text += f"| {row['duration_s']:g} | {errs} | {sig} |\n"
        shortest = shortest_for_b(rows)
        summary["record_for_B_within_10_percent_s"] = shortest
        text += (
            f"\nB within 10 % (every seed, σ_B ≤ 5 %) from a {shortest:g} s record.\n"
            if shortest is not None
            else "\nB not within 10 % on any record length tried.\n"
        )
    chain_seeds = list(range(1, (1 if quick else max(b_seeds, seeds)) + 1))
    chain_text, chain_summary = _whole_chain_table(chain_seeds, quick, progress)
    text += chain_text
    summary.update(chain_summary)
    names = list(field_accuracy.ROWS)[:1] if quick else list(field_accuracy.ROWS)
    field_rows, _ = field_accuracy.score_rows(names, chain_seeds, progress)
    summary["whole_chain_field"] = field_rows
    text += (
        "\nWhole-chain identification on drives the project never tuned on (logs from "
        "`benchmarks/simulators/field_sim.py`, a simulator written apart from the plant; "
        f"{len(chain_seeds)} seeds; `auto`; only k_t, J_m and the counts known, the friction "
        "where the row says):\n\n" + field_accuracy.markdown(field_rows)
    )
    excitation_text, excitation_summary = excitation_accuracy.table(chain_seeds, quick, progress)
    text += excitation_text
    summary.update(excitation_summary)
    load_text, load_summary = _load_torque_table(chain_seeds, quick, progress)
    text += load_text
    summary.update(load_summary)
    beam_text, beam_summary = _beam_table(chain_seeds, quick, progress)
    text += beam_text
    summary.update(beam_summary)
    broadband_fit.cache_clear()
    summary["seconds"] = time.perf_counter() - started
    out.mkdir(parents=True, exist_ok=True)
    (out / "accuracy.md").write_text(text, encoding="utf-8")
    (out / "accuracy.json").write_text(json.dumps(summary, indent=1), encoding="utf-8")
    return {"table": text, **summary}


def _load_torque_table(
    seeds: Sequence[int], quick: bool, progress: Callable[[str], None]
) -> tuple[str, dict[str, object]]:
    """The load torque rows and the bandwidth trade-off (not in quick mode)."""
    rows = load_accuracy.ROWS[:1] if quick else load_accuracy.ROWS
    load = load_accuracy.score_rows(rows, seeds, progress)
    summary: dict[str, object] = {"load_torque": load}
    text = (
        f"\nLoad torque from the motor alone (scenario `load-torque`'s profile on the chain, "
        f"{len(seeds)} seeds; errors in % of the step; the observer's default "
        "bandwidth):\n\n" + load_accuracy.markdown(load)
    )
    if not quick:
        trade = load_accuracy.bandwidth_rows(progress)
        summary["load_torque_bandwidth"] = trade
        text += (
            "\nThe load torque bandwidth's trade-off (bench, load on mass 3, seed 1):\n\n"
            + load_accuracy.bandwidth_markdown(trade)
        )
    return text, summary


def _whole_chain_table(
    seeds: Sequence[int], quick: bool, progress: Callable[[str], None]
) -> tuple[str, dict[str, object]]:
    """The whole-chain rows of the project's chains (:mod:`benchmarks.chain_accuracy`;
    quick: the bench)."""
    chains = chain_accuracy.CHAINS[:1] if quick else chain_accuracy.CHAINS
    whole = {c.name: chain_accuracy.score_chain(c, seeds, progress) for c in chains}
    text = (
        "\nWhole-chain identification (`--method whole-chain --masses auto`, scenario "
        f"`identification`, {len(seeds)} seeds; only the actuator known):\n\n"
        + chain_accuracy.markdown(whole)
    )
    return text, {"whole_chain": whole}


def _beam_table(
    seeds: Sequence[int], quick: bool, progress: Callable[[str], None]
) -> tuple[str, dict[str, object]]:
    """The flexible-link rows (:mod:`benchmarks.beam_accuracy`; quick: the first link)."""
    links = beam_accuracy.LINKS[:1] if quick else beam_accuracy.LINKS
    rows = {case.name: beam_accuracy.score(case, seeds, progress) for case in links}
    text = (
        "\nFlexible links from the hub alone (`--method beam`: logs from `benchmarks/"
        f"field_sim.py` with the link's modes, {beam_accuracy.DURATION:g} s multi-sine, "
        f"{len(seeds)} seeds; k_t, J_m, the counts, the friction, L, m_tip given):\n\n"
        + beam_accuracy.markdown(rows)
    )
    return text, {"flexible_link": rows}


def _rows_alone(
    out: Path,
    count: int,
    quick: bool,
    progress: Callable[[str], None],
    started: float,
    table: Callable[..., tuple[str, dict[str, object]]],
    stem: str,
) -> dict[str, object]:
    """One group of rows alone (``table``: seeds 1 … ``count``, one in quick mode), written
    as ``STEM.md`` and ``STEM.json`` into ``out``, with the wall time (s)."""
    seeds = list(range(1, (1 if quick else count) + 1))
    text, summary = table(seeds, quick, progress)
    summary["seconds"] = time.perf_counter() - started
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{stem}.md").write_text(text, encoding="utf-8")
    (out / f"{stem}.json").write_text(json.dumps(summary, indent=1), encoding="utf-8")
    return {"table": text, **summary, "files": (f"{stem}.md", f"{stem}.json")}


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim bench accuracy``."""
    p = subparsers.add_parser(
        "accuracy",
        help="method × case accuracy table",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--seeds", type=int, default=5, help="noise seeds per case (default 5)")
    p.add_argument(
        "--b-seeds", type=int, default=20, help="seeds for B's standard-error check (default 20)"
    )
    p.add_argument("--quick", action="store_true", help="the bench only, no long record")
    p.add_argument(
        "--load-torque-only",
        action="store_true",
        help="only the load torque rows (as many seeds as the whole-chain rows: the larger "
        "of --seeds and --b-seeds), into load_torque.md/.json",
    )
    p.add_argument(
        "--beam-only",
        action="store_true",
        help="only the flexible-link rows (as many seeds as the whole-chain rows), into "
        "beam.md/.json",
    )
    p.add_argument(
        "--whole-chain-only",
        action="store_true",
        help="only the whole-chain rows of the project's three chains (as many seeds as "
        "--b-seeds or --seeds, the larger), into whole_chain.md/.json",
    )
    p.add_argument("--out", type=Path, default=Path("reports"), help="folder for the table")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    if args.seeds < 1 or args.b_seeds < 0:
        raise UserError("--seeds must be >= 1 and --b-seeds >= 0")
    result = run(
        args.out,
        args.seeds,
        args.b_seeds,
        args.quick,
        progress=progress,
        load_torque_only=args.load_torque_only,
        beam_only=args.beam_only,
        whole_chain_only=args.whole_chain_only,
    )
    print(result["table"])
    md, js = result.get("files", ("accuracy.md", "accuracy.json"))
    print(f"wrote {args.out / md} and {args.out / js} ({result['seconds']:.0f} s)")
    return 0


if __name__ == "__main__":
    import sys

    from benchmarks import main

    sys.exit(main("accuracy", add_parser, sys.argv[1:]))
