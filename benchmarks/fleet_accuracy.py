"""``arcosim bench fleet``: the fleet's drift alarms on simulated fleets, and what a
fleet costs per log on Dask.

Each fleet is :mod:`benchmarks.simulators.fleet_sample`'s monitoring fleet (8 axes x 3 dates,
chains of n = 2 and 3, stick-slip friction on two axes, a corrupt log; k[1] 6 % then
12 % lower on ``k-drop``, the fitted Coulomb friction f_c 50 % then 100 % higher on
``friction-rise``), its noise drawn from the fleet's seed. It is identified with
:func:`arcosim.identify_fleet` on a local cluster and its drift read with
:func:`arcosim.fleet_drift` (default threshold 5 % and 3 sigma). Per fleet: the alarms
found against those expected (the right axis, parameter and sign), the false alarms
(any other), the failed logs (the corrupt one expected), the untrusted fits, the fits
with n wrong.

``--scaling``: one fleet identified on 1 and on 2 local workers: logs per minute, the
mean fit time of a log against the wall time per log and worker (the difference is
the cluster's and the store's overhead per log), each worker's peak memory, the time
to add a row to a store of 10,000 rows (:mod:`benchmarks.fleet_store`); and from these,
on paper, 10,000 logs on 64 cores.

Run: ``arcosim bench fleet [--fleets N] [--first-seed 0] [--seconds 20] [--workers 2]
[--out FILE.json]`` or ``arcosim bench fleet --scaling`` (about 8 s of simulation and 6 s
of fit per 20 s log on the loaded 2-core machine; 25 logs a fleet).
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import sys
import tempfile
import time
from pathlib import Path

import arcosim
from arcosim import UserError
from arcosim.experiments import markdown_table
from arcosim.fleet import AxisDrift, DriftReport, read_store
from benchmarks.fleet_store import per_row
from benchmarks.simulators.fleet_sample import MONITORING, write_monitoring_fleet

#: Logs of the paper estimate, and its cores.
PAPER_LOGS, PAPER_CORES = 10_000, 64


def expected_alarms() -> set[tuple[str, str, int]]:
    """(axis, parameter, sign) of every alarm the monitoring fleet should raise."""
    return {(axis, p, sign) for axis, plan in MONITORING.items() for p, sign in plan.expect}


def found_alarms(report: DriftReport) -> set[tuple[str, str, int]]:
    """(axis, parameter, sign) of every alarm of ``report`` (a structure alarm: ``n``)."""
    found = set()
    for axis, drift in report.axes.items():
        for alarm in drift.alarms:
            if alarm["kind"] == "structure":
                found.add((axis, "n", int(math.copysign(1, alarm["latest"] - alarm["baseline"]))))
            else:
                found.add((axis, alarm["parameter"], int(math.copysign(1, alarm["change"]))))
    return found


def score_fleet(seed: int, seconds: float, workers: int, folder: Path) -> dict:
    """Write, identify and read the drift of the monitoring fleet of ``seed``."""
    started = time.perf_counter()
    write_monitoring_fleet(folder / "fleet", seed, seconds, progress=_progress)
    simulated = time.perf_counter() - started
    run = arcosim.identify_fleet(
        folder / "fleet", folder / "out", workers=workers, progress=sys.stderr
    )
    report = arcosim.fleet_drift(folder / "out")
    rows = read_store(folder / "out")
    expected, found = expected_alarms(), found_alarms(report)
    changes = {}
    for axis, parameter, _ in sorted(expected):
        for change in report.axes[axis].changes:
            if change["parameter"] == parameter:
                changes[f"{axis} {parameter}"] = {
                    "change": change["change"],
                    "sigmas": change["sigmas"],
                }
    ok = [r for r in rows if r["status"] == "ok"]
    trusted = [r for r in ok if r["verdict"] == "trusted"]
    healthy = [report.axes[a] for a, plan in MONITORING.items() if not plan.expect]
    return {
        "seed": seed,
        "logs": run.total,
        "expected": sorted(expected),
        "found": sorted(found & expected),
        "missed": sorted(expected - found),
        "false": sorted(found - expected),
        "healthy_comparisons": sum(comparisons(drift) for drift in healthy),
        "healthy_false": sum(len(drift.alarms) for drift in healthy),
        "failed": [f"{f['axis']} {f['date']}: {f['reason']}" for f in report.failed],
        "untrusted": [
            f"{r['axis']} {r['date']}: {r['verdict_reasons']}" for r in ok if r not in trusted
        ],
        "n_wrong": [
            f"{r['axis']} {r['date']}: n = {r['n']}"
            for r in trusted
            if r["n"] != MONITORING[str(r["axis"])].n
        ],
        "changes": changes,
        "simulated_s": simulated,
        "identified_s": run.seconds,
        "fit_s": [float(r["seconds"]) for r in rows],
    }


def comparisons(drift: AxisDrift) -> int:
    """The comparisons the rule made on one axis: each parameter compared, or the one
    of n when it differed (then no parameter is compared); none without a latest fit."""
    return len(drift.changes) + sum(1 for a in drift.alarms if a["kind"] == "structure")


def false_alarm_rate(fleets: list[dict]) -> str:
    """The false alarms on the unchanged axes per comparison, over ``fleets``, with the
    one-sided 95 % upper bound of the rate (exact binomial, Clopper–Pearson)."""
    from scipy.stats import beta

    count = sum(f["healthy_comparisons"] for f in fleets)
    false = sum(f["healthy_false"] for f in fleets)
    if not count:
        return "false alarms on unchanged axes: no comparison made"
    upper = float(beta.ppf(0.95, false + 1, count - false))
    return (
        f"false alarms on unchanged axes: {false} of {count} parameter comparisons "
        f"({false / count:.2%}; 95 % upper bound {upper:.2%}) over {len(fleets)} fleets"
    )


def accuracy_table(fleets: list[dict]) -> str:
    """The markdown table of :func:`score_fleet`'s results, a row per fleet."""
    head = [
        "seed",
        "logs",
        "alarms found",
        "false alarms",
        "unchanged axes' comparisons",
        "false on them",
        "failed logs",
        "untrusted",
        "n wrong",
        "identify (s)",
    ]
    rows = [
        [
            str(f["seed"]),
            str(f["logs"]),
            f"{len(f['found'])}/{len(f['expected'])}",
            str(len(f["false"])),
            str(f["healthy_comparisons"]),
            str(f["healthy_false"]),
            str(len(f["failed"])),
            str(len(f["untrusted"])),
            str(len(f["n_wrong"])),
            f"{f['identified_s']:.0f}",
        ]
        for f in fleets
    ]
    return markdown_table(head, rows)


def _peak_memory() -> float:
    """This process's peak resident memory (MB), run on each worker."""
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def scaling(folder: Path, seconds: float, worker_counts: tuple[int, ...] = (1, 2)) -> dict:
    """One fleet identified on each number of local workers; the figures per log."""
    from dask.distributed import Client, LocalCluster

    fleet = folder / "0" / "fleet"  # the first fleet of an accuracy run, when kept
    if not fleet.is_dir():
        write_monitoring_fleet(fleet, 0, seconds, progress=_progress)
    runs = {}
    for workers in worker_counts:
        out = folder / f"out-{workers}"
        shutil.rmtree(out, ignore_errors=True)  # a store from before would skip every log
        started = time.perf_counter()
        with LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster:
            ready = time.perf_counter() - started
            run = arcosim.identify_fleet(
                fleet, out, scheduler=cluster.scheduler_address, progress=sys.stderr
            )
            with Client(cluster) as client:
                memory = sorted(client.run(_peak_memory).values())
        rows = read_store(out)
        fits = [float(r["seconds"]) for r in rows]
        runs[workers] = {
            "logs": run.identified,
            "start_s": ready,
            "wall_s": run.seconds,
            "logs_per_minute": 60 * run.identified / run.seconds,
            "fit_s_mean": sum(fits) / len(fits),
            "fit_s_ok_mean": _mean([float(r["seconds"]) for r in rows if r["status"] == "ok"]),
            "overhead_s_per_log": (workers * run.seconds - sum(fits)) / len(fits),
            "peak_memory_mb": memory,
        }
    store = per_row(folder / "store", PAPER_LOGS)
    return {"runs": runs, "store_10k_s": store, "paper": paper(runs, store["append"])}


def _mean(values: list[float]) -> float:
    return sum(values) / len(values) if values else math.nan


def paper(runs: dict, store_s: float) -> dict:
    """10,000 logs on 64 cores, on paper, from the one-worker run: the workers' time (a
    log's fit and overhead, spread over 64) and the client's (a row appended to the
    store per log, ``store_s`` each at 10,000 rows)."""
    one = runs[min(runs)]
    per_log = one["fit_s_mean"] + max(one["overhead_s_per_log"], 0.0)
    workers_s = PAPER_LOGS * per_log / PAPER_CORES
    client_s = PAPER_LOGS * store_s
    return {
        "per_log_s": per_log,
        "workers_s": workers_s,
        "client_store_s": client_s,
        "bound_s": max(workers_s, client_s),
    }


def scaling_text(result: dict) -> str:
    """The scaling figures for a reader."""
    head = [
        "workers",
        "logs",
        "cluster start (s)",
        "wall (s)",
        "logs/min",
        "fit per log (s)",
        "wall x workers per log (s)",
        "overhead per log (s)",
        "peak memory per worker (MB)",
    ]
    rows = [
        [
            str(w),
            str(r["logs"]),
            f"{r['start_s']:.1f}",
            f"{r['wall_s']:.1f}",
            f"{r['logs_per_minute']:.1f}",
            f"{r['fit_s_mean']:.2f}",
            f"{w * r['wall_s'] / r['logs']:.2f}",
            f"{r['overhead_s_per_log']:.2f}",
            ", ".join(f"{m:.0f}" for m in r["peak_memory_mb"]),
        ]
        for w, r in result["runs"].items()
    ]
    p, store = result["paper"], result["store_10k_s"]
    lines = [
        markdown_table(head, rows),
        "",
        f"store of {PAPER_LOGS} rows: a row appended in {1e3 * store['append']:.2f} ms "
        f"(the whole store rewritten, as before: {store['rewrite']:.2f} s)",
        f"on paper, {PAPER_LOGS} logs on {PAPER_CORES} cores: {p['per_log_s']:.2f} s a log "
        f"(fit and overhead, one worker) x {PAPER_LOGS} / {PAPER_CORES} = "
        f"{p['workers_s'] / 60:.0f} min of the workers; the client appends a row per log, "
        f"{PAPER_LOGS} x {1e3 * store['append']:.2f} ms = {p['client_store_s']:.0f} s; "
        f"the run takes at least {p['bound_s'] / 60:.0f} min (the larger)",
    ]
    return "\n".join(lines)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the benchmark ``fleet``."""
    p = subparsers.add_parser(
        "fleet",
        help="the fleet's drift alarms on simulated fleets, and its cost per log on Dask",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--fleets", type=int, default=5, help="fleets (default 5)")
    p.add_argument("--first-seed", type=int, default=0, help="the first fleet's seed")
    p.add_argument("--seconds", type=float, default=20.0, help="each log's length (s)")
    p.add_argument("--workers", type=int, default=2, help="local workers (default 2)")
    p.add_argument(
        "--scaling",
        action="store_true",
        help="instead: one fleet on 1 and 2 workers, the cost per log",
    )
    p.add_argument(
        "--keep",
        type=Path,
        help="write the fleets and stores here (kept; --scaling reuses fleet 0)",
    )
    p.add_argument("--out", type=Path, help="also write the results as JSON")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    if args.fleets < 1 or args.workers < 1 or not args.seconds > 0:
        raise UserError("--fleets and --workers must be >= 1 and --seconds > 0")
    with tempfile.TemporaryDirectory(prefix="arcosim-fleet-") as temporary:
        folder = args.keep or Path(temporary)
        if args.scaling:
            result = scaling(folder, args.seconds)
            print(scaling_text(result))
        else:
            fleets = []
            for seed in range(args.first_seed, args.first_seed + args.fleets):
                fleets.append(score_fleet(seed, args.seconds, args.workers, folder / f"{seed}"))
                print(_fleet_text(fleets[-1]), flush=True)
                if args.out:  # after each fleet: a long run stopped keeps what it scored
                    args.out.write_text(json.dumps({"fleets": fleets}, indent=1, default=str))
            result = {"fleets": fleets}
            print(accuracy_table(fleets))
            print(false_alarm_rate(fleets))
    if args.out:
        args.out.write_text(json.dumps(result, indent=1, default=str))
        print(f"wrote {args.out}")
    return 0


def _fleet_text(fleet: dict) -> str:
    """One fleet's alarms, failures and untrusted fits, a line each."""
    lines = [
        f"fleet {fleet['seed']}: {fleet['logs']} logs, simulated in "
        f"{fleet['simulated_s']:.0f} s, identified in {fleet['identified_s']:.0f} s"
    ]
    for key, c in fleet["changes"].items():
        sigmas = "no std" if c["sigmas"] is None else f"{c['sigmas']:+.1f} sigma"
        lines.append(f"  expected {key}: {c['change']:+.1%} ({sigmas})")
    lines += [f"  found {a} {p} {s:+d}" for a, p, s in fleet["found"]]
    lines += [f"  MISSED {a} {p} {s:+d}" for a, p, s in fleet["missed"]]
    lines += [f"  FALSE ALARM {a} {p} {s:+d}" for a, p, s in fleet["false"]]
    lines += [f"  failed {f}" for f in fleet["failed"]]
    lines += [f"  untrusted {u[:160]}" for u in fleet["untrusted"]]
    lines += [f"  n wrong {u}" for u in fleet["n_wrong"]]
    return "\n".join(lines)


def _progress(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


if __name__ == "__main__":
    from benchmarks import main

    sys.exit(main("fleet", add_parser, sys.argv[1:]))
