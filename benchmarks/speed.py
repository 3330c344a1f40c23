"""Speed of the co-simulation, of each FMU's step and of identification:
``arcosim bench speed [--quick] [--runs R] [--out DIR]`` (or ``python -m benchmarks.speed``).

Every figure is the median over R runs (spread: min–max) on this machine:

* the bench co-simulation (C plant + pythonfmu observer, 1 kHz, 10 s, realistic
  sensors, the ``flexible`` scenario, mode 2, default estimator) through
  :func:`arcosim.host.master.cosimulate`: µs per 1 ms step of the whole loop;
* the same loop instrumented call by call: each FMU's ``fmi2DoStep`` and its set/get
  traffic, through the same raw ctypes calls as the master, plus the observer's
  estimates read every step as a controller would (the timer's own overhead, shown
  in its row, is included in every row);
* the observer's algorithms stepped in plain Python (no FMI), over the same signals;
* the whole loop for n = 1, 3, 10, 20 masses and for 1, 10, 100 s records;
* output-error identification (:mod:`arcosim.identification.fit.uniform_fit`) of a 10 s
  bench record, and whole-chain identification of the field drives
  (:mod:`benchmarks.field_accuracy`).

Writes ``throughput.md`` and ``throughput.json`` into ``--out`` (default reports/).
``--quick`` proves the benchmark runs (one run, short records, n = 1 and 3); its
figures are not the ones to quote.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import statistics
import time
from collections.abc import Callable, Iterator, Sequence
from ctypes import c_double
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from arcosim import SCENARIOS, FmuInstance, UserError, cosimulate, ensure_built
from arcosim.build import OBSERVER, PLANT
from arcosim.experiments import markdown_table
from arcosim.fmu.flexchain import Mode
from arcosim.host import MEASURED
from benchmarks import field_accuracy

H = 1e-3
OBSERVER_SETTINGS = {"mode": 2}


@dataclass(frozen=True)
class Figure:
    """A median with its spread over runs (same unit as the samples)."""

    median: float
    low: float
    high: float

    @staticmethod
    def of(samples: Sequence[float]) -> Figure:
        return Figure(statistics.median(samples), min(samples), max(samples))

    def cell(self, digits: int = 1) -> str:
        return f"{self.median:.{digits}f} ({self.low:.{digits}f}–{self.high:.{digits}f})"


@contextlib.contextmanager
def _bench_pair(n: int) -> Iterator[tuple[FmuInstance, FmuInstance]]:
    """The plant and the observer FMUs for n masses, instantiated (closed on exit)."""
    folder = ensure_built(n)
    with (
        FmuInstance(folder / f"{PLANT.name}.fmu", "plant") as plant,
        FmuInstance(folder / f"{OBSERVER.name}.fmu", "observer") as obs,
    ):
        yield plant, obs


def _current(duration: float) -> np.ndarray:
    t = np.arange(round(duration / H)) * H
    return SCENARIOS["flexible"].current(t)


def whole_loop(n: int, duration: float, observer: dict | None = None) -> float:
    """µs per step of one :func:`cosimulate` run of ``duration`` s with n masses."""
    current = _current(duration)
    with _bench_pair(n) as (plant, obs):
        started = time.perf_counter()
        cosimulate(
            plant,
            obs,
            current,
            H,
            ["theta_m_true"],
            ["tau_reac_hat"],
            observer_parameters={**OBSERVER_SETTINGS, **(observer or {})},
            record_every=len(current),
        )
        return (time.perf_counter() - started) / len(current) * 1e6


def split_loop(duration: float) -> dict[str, float]:
    """µs per step of each part of the bench loop: the master's raw calls timed one by
    one, plus the read of the estimates a controller would make every step."""
    current = _current(duration).tolist()
    clock = time.perf_counter_ns
    with _bench_pair(3) as (plant, obs):
        plant.initialize()
        measured, observer_in = plant.real_port(MEASURED), obs.real_port(MEASURED)
        measured.get()
        observer_in.send(measured.values)
        obs.initialize(OBSERVER_SETTINGS)
        estimates = obs.real_port(["tau_reac_hat", "theta_hat[1]", "theta_hat[2]", "theta_hat[3]"])
        i_port = plant.real_port(["i_ref"])
        set_i, i_vr, i_value, one = i_port.set_real, i_port.vrs, i_port.values, i_port.count
        plant_step, pc = plant.step_call()
        observer_step, oc = obs.step_call()
        get_sensors, sensors_in = measured.get_real, observer_in.set_real
        vrs_out, vrs_in, values = measured.vrs, observer_in.vrs, measured.values
        count = measured.count
        get_estimates, vrs_est, n_est, est = (
            estimates.get_real,
            estimates.vrs,
            estimates.count,
            estimates.values,
        )
        t_c, h_c = c_double(0.0), c_double(H)
        totals = [0] * 6
        for k, i_ref in enumerate(current):  # the calls of cosimulate's loop, timed apart
            t_c.value = k * H
            t0 = clock()
            i_value[0] = i_ref
            set_i(pc, i_vr, one, i_value)
            t1 = clock()
            plant_step(pc, t_c, h_c, 1)
            t2 = clock()
            get_sensors(pc, vrs_out, count, values)
            t3 = clock()
            sensors_in(oc, vrs_in, count, values)
            t4 = clock()
            observer_step(oc, t_c, h_c, 1)
            t5 = clock()
            get_estimates(oc, vrs_est, n_est, est)
            t6 = clock()
            for j, (a, b) in enumerate(
                ((t0, t1), (t1, t2), (t2, t3), (t3, t4), (t4, t5), (t5, t6))
            ):
                totals[j] += b - a
        timer = 0
        for _ in current:
            t0 = clock()
            timer += clock() - t0
    plant_set, plant_do, plant_get, obs_set, obs_do, obs_get = (
        x / len(current) / 1e3 for x in totals
    )
    return {
        "plant doStep": plant_do,
        "plant set i_ref + get sensors": plant_set + plant_get,
        "observer doStep": obs_do,
        "observer set sensors": obs_set,
        "observer get τ̂_reac, θ̂_1…θ̂_3": obs_get,
        "observer whole step (set + doStep + get)": obs_set + obs_do + obs_get,
        "timer overhead per timed call (in each row)": timer / len(current) / 1e3,
    }


@functools.lru_cache(maxsize=2)
def _bench_sensors(duration: float) -> tuple[list[float], list[float], list[float]]:
    """i_a, ω_m, θ_m of the bench co-simulation of ``duration`` s (simulated once)."""
    with _bench_pair(3) as (plant, obs):
        rec = cosimulate(
            plant, obs, _current(duration), H, list(MEASURED), [], None, OBSERVER_SETTINGS
        )
    i_a, w, th = (rec[f"plant.{c}"].tolist() for c in MEASURED)
    return i_a, w, th


def plain_python_step(duration: float) -> float:
    """µs per step of the observer's algorithms (flexchain) with no FMI in between."""
    from arcosim.fmu.flexchain import Observer
    from benchmarks.cases import CASES, settings_for

    i_a, w, th = _bench_sensors(duration)
    observer = Observer(settings_for(CASES[0], Mode.STATE_ESTIMATION), th[0], w[0])
    step = observer.step
    started = time.perf_counter()
    for k in range(1, len(th)):
        step(H, i_a[k], w[k], th[k])
    return (time.perf_counter() - started) / (len(th) - 1) * 1e6


def identification_seconds(duration: float) -> float:
    """Seconds to identify k and B by output error from a ``duration`` s bench record."""
    from benchmarks.accuracy import broadband, fit_broadband
    from benchmarks.cases import CASES

    log = broadband(CASES[0], seed=1, duration=duration)
    started = time.perf_counter()
    fit_broadband(CASES[0], log)
    return time.perf_counter() - started


def run(out: Path, runs: int, quick: bool, progress: Callable[[str], None] = print) -> dict:
    """Run every measurement ``runs`` times; write ``throughput.md`` and ``.json``."""
    masses = (1, 3) if quick else (1, 3, 10, 20)
    lengths = (1.0, 2.0) if quick else (1.0, 10.0, 100.0)
    base = 2.0 if quick else 10.0
    for n in masses:
        ensure_built(n)
    results: dict[str, object] = {"runs": runs, "quick": quick, "record_s": base}

    def repeat(label: str, measure: Callable[[], float]) -> Figure:
        progress(label)
        return Figure.of([measure() for _ in range(runs)])

    loop = repeat("bench loop", lambda: whole_loop(3, base))
    model_based = repeat("bench loop, model-based", lambda: whole_loop(3, base, {"estimator": 1}))
    parts = []
    for _ in range(runs):
        progress("bench loop, call by call")
        parts.append(split_loop(base))
    split = {name: Figure.of([p[name] for p in parts]) for name in parts[0]}
    plain = repeat("observer in plain Python", lambda: plain_python_step(base))
    by_n = {n: repeat(f"n = {n}", lambda n=n: whole_loop(n, base)) for n in masses}
    by_length = {
        d: repeat(f"{d:g} s record", lambda d=d: whole_loop(3, d) * d / H / 1e6) for d in lengths
    }
    oe = repeat("output-error identification", lambda: identification_seconds(10.0))
    progress("whole-chain identification")
    whole = field_accuracy.speed(repeats=1 if quick else max(runs, 3), quick=quick)
    results.update(
        {
            "bench_loop_us": vars(loop),
            "bench_loop_model_based_us": vars(model_based),
            "split_us": {k: vars(v) for k, v in split.items()},
            "plain_python_observer_us": vars(plain),
            "loop_us_by_masses": {str(n): vars(f) for n, f in by_n.items()},
            "run_seconds_by_record": {f"{d:g}": vars(f) for d, f in by_length.items()},
            "output_error_10s_seconds": vars(oe),
            "whole_chain_seconds": whole,
        }
    )
    text = markdown(loop, model_based, split, plain, by_n, by_length, oe, base, runs, quick)
    text += (
        "\nWhole-chain identification (log → result, the simulation excluded; drives of "
        "`benchmarks/field_accuracy.py`; one BLAS thread):\n\n"
        + field_accuracy.speed_markdown(whole)
    )
    out.mkdir(parents=True, exist_ok=True)
    (out / "throughput.md").write_text(text, encoding="utf-8")
    (out / "throughput.json").write_text(json.dumps(results, indent=1), encoding="utf-8")
    return {"table": text, **results}


def markdown(loop, model_based, split, plain, by_n, by_length, oe, base, runs, quick) -> str:
    """The report: medians with min–max over runs."""
    steps = [
        ["bench co-simulation, whole loop (recursion, default)", loop.cell()],
        ["bench co-simulation, whole loop (model-based observer)", model_based.cell()],
        *([f"of the loop: {name}", f.cell(2)] for name, f in split.items()),
        ["observer algorithms in plain Python, no FMI", plain.cell(2)],
    ]
    three = by_n[3].median
    masses = [[n, f.cell(), f"{f.median / three:.2f}"] for n, f in by_n.items()]
    first = next(iter(by_length.values())).median
    records = [[f"{d:g} s", f.cell(3), f"{f.median / first:.1f}"] for d, f in by_length.items()]
    lines = [
        f"Median (min–max) over {runs} run(s); {base:g} s records at 1 kHz"
        + (" — quick mode, not figures to quote" if quick else "")
        + ".",
        "",
        markdown_table(["what", "µs per 1 ms step"], steps),
        "",
        markdown_table(["load masses n", "µs per step, whole loop", "× n = 3"], masses),
        "",
        markdown_table(["record", "seconds, whole run", "× shortest"], records),
        "",
        f"Output-error identification of a 10 s bench record: {oe.cell(2)} s.",
    ]
    return "\n".join(lines) + "\n"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim bench speed``."""
    p = subparsers.add_parser(
        "speed",
        help="µs per step of the co-simulation and its parts",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--runs", type=int, default=5, help="runs per figure (default 5)")
    p.add_argument("--quick", action="store_true", help="one run, short records, n = 1 and 3")
    p.add_argument("--out", type=Path, default=Path("reports"), help="folder for the table")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    runs = 1 if args.quick else args.runs
    if runs < 1:
        raise UserError(f"--runs {args.runs}: run each measurement at least once")
    result = run(args.out, runs, args.quick, progress=lambda s: print(f"  … {s}", flush=True))
    print(result["table"])
    print(f"wrote {args.out / 'throughput.md'} and {args.out / 'throughput.json'}")
    return 0


if __name__ == "__main__":
    import sys

    from benchmarks import main

    sys.exit(main("speed", add_parser, sys.argv[1:]))
