"""``arcosim sweep SPEC.toml``: Monte Carlo and grid sweeps of co-simulations on Dask.

    arcosim sweep SPEC.toml [--scheduler ADDRESS] [--workers N] [--out DIR] [--resume]

A spec names the scenario, the parameters to vary by FMU and variable (as in
``arcosim simulate``: ``plant.i_noise_std``, ``observer.g_dist``), how to draw them,
the number of runs, and the metrics to collect::

    name = "noise-encoder-gdist"
    scenario = "rigid"          # any scenario of `arcosim simulate`
    masses = 3
    runs = 200                  # random draws (a grid's size comes from the grid)
    seed = 42
    metrics = ["k_error", "B_error", "runtime"]

    [fixed]
    "observer.D_m" = 2e-5

    [vary]
    "plant.i_noise_std" = { distribution = "uniform", low = 0.0, high = 0.02 }
    "plant.encoder_cpr" = { distribution = "choice", values = [500, 2000, 8192] }
    "observer.g_dist" = { distribution = "loguniform", low = 50.0, high = 400.0 }
    "plant.seed" = { distribution = "randint", low = 1, high = 1000000 }

Distributions: ``uniform``, ``loguniform`` (low, high), ``normal`` (mean, std),
``randint`` (low, high, high excluded), ``choice`` (values), ``grid`` (values; all
varied parameters must then be grids, and the runs are their product). Every run's
values are drawn up front from ``seed``, so a spec gives the same runs every time.

Metrics: ``k_error``, ``B_error`` (mode 1, % against the plant's k[1], B[1]),
``D_m_error``, ``f_c_error`` (mode 0, %), ``theta_error`` (mode 2, METHOD.md's score
per mass), ``runtime`` (s per run).

Without ``--scheduler`` a ``dask.distributed.LocalCluster`` of ``--workers``
processes runs here; with it the same tasks go to that cluster. Each run is a task
that builds nothing: the FMUs are built once and shipped as bytes. Rows are appended
to ``results.csv`` as runs finish, so an interrupted sweep keeps every finished run
and ``--resume`` runs only the others; a failed run records its error and the sweep
goes on. At the end ``summary.md`` holds metric quantiles per varied parameter and
the PNGs the error histograms and the errors against each parameter.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import hashlib
import itertools
import math
import sys
import tempfile
import time
import traceback
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cosim.build import OBSERVER, PLANT, check_masses, ensure_built
from cosim.errors import UserError
from cosim.overrides import check_name, typed_value

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

KEYS = {
    "name",
    "scenario",
    "masses",
    "runs",
    "seed",
    "metrics",
    "fixed",
    "vary",
    "duration",
    "step",
    "ideal",
}
DISTRIBUTIONS = {
    "uniform": ("low", "high"),
    "loguniform": ("low", "high"),
    "normal": ("mean", "std"),
    "randint": ("low", "high"),
    "choice": ("values",),
    "grid": ("values",),
}
METRICS = ("k_error", "B_error", "D_m_error", "f_c_error", "theta_error", "runtime")


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep specification (see module doc)."""

    name: str
    scenario: str
    masses: int
    runs: int
    seed: int
    metrics: tuple[str, ...]
    fixed: dict[str, object] = field(default_factory=dict)
    vary: dict[str, dict] = field(default_factory=dict)
    duration: float | None = None
    step: float = 1e-3
    ideal: bool = False


def load_spec(path: Path) -> SweepSpec:
    """Read and check a spec; every mistake is a :class:`UserError` naming it."""
    from cosim.scenarios import SCENARIOS

    path = Path(path)
    if not path.is_file():
        raise UserError(f"{path}: no such file")
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as error:
        raise UserError(f"{path}: not valid TOML ({error})") from None
    unknown = set(raw) - KEYS
    if unknown:
        raise UserError(
            f"{path}: unknown key {', '.join(sorted(unknown))} (known: {', '.join(sorted(KEYS))})"
        )
    scenario = raw.get("scenario", "rigid")
    if scenario not in SCENARIOS:
        raise UserError(f"{path}: scenario {scenario!r} is not one of {', '.join(SCENARIOS)}")
    metrics = tuple(raw.get("metrics", ["k_error", "B_error", "runtime"]))
    for metric in metrics:
        if metric not in METRICS:
            raise UserError(f"{path}: metric {metric!r} is not one of {', '.join(METRICS)}")
    vary = raw.get("vary", {})
    for name, dist in vary.items():
        _check_distribution(path, name, dist)
    grids = [n for n, d in vary.items() if d["distribution"] == "grid"]
    if grids and len(grids) != len(vary):
        raise UserError(
            f"{path}: a grid cannot be mixed with random distributions "
            f"({', '.join(grids)} are grids)"
        )
    runs = int(raw.get("runs", 0 if grids else 1))
    if not grids and runs < 1:
        raise UserError(f"{path}: runs = {runs}: at least one run")
    for name in [*vary, *raw.get("fixed", {})]:
        if name.split(".", 1)[0] not in ("plant", "observer") or "." not in name:
            raise UserError(f"{path}: {name!r}: name the FMU first (plant.NAME or observer.NAME)")
    duration = raw.get("duration")
    if duration is not None and not duration > 0:
        raise UserError(f"{path}: duration = {duration}: it must be > 0 s")
    return SweepSpec(
        name=str(raw.get("name", path.stem)),
        scenario=scenario,
        masses=check_masses(int(raw.get("masses", 3))),
        runs=runs,
        seed=int(raw.get("seed", 0)),
        metrics=metrics,
        fixed=dict(raw.get("fixed", {})),
        vary=dict(vary),
        duration=duration,
        step=float(raw.get("step", 1e-3)),
        ideal=bool(raw.get("ideal", False)),
    )


def _check_distribution(path: Path, name: str, dist: object) -> None:
    if not isinstance(dist, dict) or "distribution" not in dist:
        raise UserError(f'{path}: {name}: write {{ distribution = "uniform", low = …, high = … }}')
    kind = dist["distribution"]
    if kind not in DISTRIBUTIONS:
        raise UserError(
            f"{path}: {name}: unknown distribution {kind!r} (use {', '.join(DISTRIBUTIONS)})"
        )
    missing = [k for k in DISTRIBUTIONS[kind] if k not in dist]
    if missing:
        raise UserError(f"{path}: {name}: a {kind} distribution needs {', '.join(missing)}")
    if kind in ("choice", "grid") and (not isinstance(dist["values"], list) or not dist["values"]):
        raise UserError(f"{path}: {name}: values must be a non-empty list")
    if kind in ("uniform", "loguniform", "randint") and not dist["low"] < dist["high"]:
        raise UserError(f"{path}: {name}: low = {dist['low']} must be below high = {dist['high']}")
    if kind == "loguniform" and not dist["low"] > 0:
        raise UserError(f"{path}: {name}: a loguniform distribution needs low > 0")
    if kind == "normal" and not dist["std"] > 0:
        raise UserError(f"{path}: {name}: std = {dist['std']} must be > 0")


def check_names(spec: SweepSpec, variables: Mapping[str, Mapping[str, object]]) -> None:
    """Refuse parameter names the FMUs do not have, and values of the wrong type."""
    for qualified, value in [*spec.fixed.items(), *((n, None) for n in spec.vary)]:
        fmu, name = qualified.split(".", 1)
        check_name(name, variables[fmu], fmu)
        var = variables[fmu][name]
        if var.causality != "parameter":
            raise UserError(f"{qualified} is an {var.causality}, not a parameter")
        if value is not None:
            typed_value(qualified, str(value), var.type)


def draw_runs(spec: SweepSpec) -> list[dict[str, object]]:
    """Every run's varied values, drawn from ``spec.seed`` (the same every time)."""
    names = list(spec.vary)
    if names and all(spec.vary[n]["distribution"] == "grid" for n in names):
        combos = itertools.product(*(spec.vary[n]["values"] for n in names))
        return [dict(zip(names, c)) for c in combos]
    rng = np.random.default_rng(spec.seed)
    runs = []
    for _ in range(spec.runs):
        values = {}
        for name in names:
            d = spec.vary[name]
            kind = d["distribution"]
            if kind == "uniform":
                values[name] = float(rng.uniform(d["low"], d["high"]))
            elif kind == "loguniform":
                values[name] = float(math.exp(rng.uniform(math.log(d["low"]), math.log(d["high"]))))
            elif kind == "normal":
                values[name] = float(rng.normal(d["mean"], d["std"]))
            elif kind == "randint":
                values[name] = int(rng.integers(d["low"], d["high"]))
            else:
                values[name] = d["values"][int(rng.integers(len(d["values"])))]
        runs.append(values)
    return runs


def metric_columns(spec: SweepSpec) -> list[str]:
    """Result columns of the requested metrics (theta_error gives one per mass)."""
    columns = []
    for metric in spec.metrics:
        if metric == "theta_error":
            columns += [f"theta_error[{i}]" for i in range(1, spec.masses + 1)]
        else:
            columns.append(metric)
    return columns


def run_one(
    run: int, values: Mapping[str, object], spec: SweepSpec, blobs: Mapping[str, bytes]
) -> dict:
    """One co-simulation (a Dask task): returns its row, with ``error`` set on failure."""
    row: dict[str, object] = {"run": run, **values}
    start = time.perf_counter()
    try:
        folder = _materialize(blobs)
        row.update(_metrics(spec, folder, values))
        row["error"] = ""
    except Exception as error:  # a failed run is recorded, the sweep goes on
        text = " | ".join(line.strip() for line in str(error).splitlines() if line.strip())
        row["error"] = f"{type(error).__name__}: {text}"[:400]
        if not isinstance(error, UserError):
            row["error"] += " | " + traceback.format_exc(limit=1).strip().splitlines()[-1][:200]
    if "runtime" in spec.metrics:
        row["runtime"] = time.perf_counter() - start
    return row


def _materialize(blobs: Mapping[str, bytes]) -> Path:
    """Write the shipped FMUs once per worker machine, into a folder named by their hash."""
    digest = hashlib.sha256(b"".join(blobs[k] for k in sorted(blobs))).hexdigest()[:16]
    folder = Path(tempfile.gettempdir()) / f"arcosim_sweep_{digest}"
    if not all((folder / name).is_file() for name in blobs):
        folder.mkdir(parents=True, exist_ok=True)
        for name, data in blobs.items():
            part = folder / f"{name}.{time.time_ns()}.part"
            part.write_bytes(data)
            part.replace(folder / name)
    return folder


def _metrics(spec: SweepSpec, folder: Path, values: Mapping[str, object]) -> dict[str, float]:
    from fmpy import read_model_description

    from cosim.scenarios import SCENARIOS, run_scenario
    from flexchain import bench

    settings = {**spec.fixed, **values}
    variables = {
        "plant": {
            v.name: v
            for v in read_model_description(str(folder / f"{PLANT.name}.fmu")).modelVariables
        },
        "observer": {
            v.name: v
            for v in read_model_description(str(folder / f"{OBSERVER.name}.fmu")).modelVariables
        },
    }
    typed: dict[str, dict[str, object]] = {"plant": {}, "observer": {}}
    for qualified, value in settings.items():
        fmu, name = qualified.split(".", 1)
        typed[fmu][name] = typed_value(qualified, str(value), variables[fmu][name].type)
    scenario = SCENARIOS[spec.scenario]
    if spec.duration is not None:
        scenario = dataclasses.replace(scenario, duration=spec.duration)
    n = spec.masses
    record_plant = ["theta_m_true", *(f"theta[{i}]" for i in range(1, n + 1))]
    record_observer = [
        "k_hat",
        "B_hat",
        "D_m_hat",
        "f_c_hat",
        *(f"theta_hat[{i}]" for i in range(1, n + 1)),
    ]
    r = run_scenario(
        scenario,
        n,
        typed["plant"],
        typed["observer"],
        h=spec.step,
        ideal=spec.ideal,
        record_plant=record_plant,
        record_observer=record_observer,
        fmu_dir=folder,
    )
    plant = typed["plant"]

    def pct(estimate: float, truth: float) -> float:
        return 100.0 * (estimate / truth - 1.0)

    out: dict[str, float] = {}
    for metric in spec.metrics:
        if metric == "k_error":
            out[metric] = pct(r["observer.k_hat"][-1], plant.get("k[1]", bench.K))
        elif metric == "B_error":
            out[metric] = pct(r["observer.B_hat"][-1], plant.get("B[1]", bench.B))
        elif metric == "D_m_error":
            out[metric] = pct(r["observer.D_m_hat"][-1], plant.get("D_m", bench.D_M))
        elif metric == "f_c_error":
            out[metric] = pct(r["observer.f_c_hat"][-1], plant.get("f_c", bench.F_C))
        elif metric == "theta_error":
            motor = r["plant.theta_m_true"]
            for i in range(1, n + 1):
                truth = r[f"plant.theta[{i}]"]
                est = r[f"observer.theta_hat[{i}]"]
                out[f"theta_error[{i}]"] = float(
                    np.sqrt(
                        np.mean((est - truth) ** 2) / max(np.mean((truth - motor) ** 2), 1e-300)
                    )
                )
    return out


def sweep(
    spec: SweepSpec,
    out: Path,
    scheduler: str | None = None,
    workers: int = 2,
    resume: bool = False,
    show_progress: bool = True,
) -> Path:
    """Run the sweep; return the results CSV (see module doc)."""
    from fmpy import read_model_description

    folder = ensure_built(spec.masses)
    fmus = {f"{r.name}.fmu": folder / f"{r.name}.fmu" for r in (PLANT, OBSERVER)}
    variables = {
        prefix: {
            v.name: v for v in read_model_description(str(fmus[f"{r.name}.fmu"])).modelVariables
        }
        for prefix, r in (("plant", PLANT), ("observer", OBSERVER))
    }
    check_names(spec, variables)
    runs = draw_runs(spec)
    columns = ["run", *spec.vary, *metric_columns(spec), "error"]
    out.mkdir(parents=True, exist_ok=True)
    results = out / "results.csv"
    done = _finished_runs(results, columns) if resume else set()
    if results.exists() and not resume:
        raise UserError(
            f"{results} exists: add --resume to finish that sweep, or choose another --out"
        )
    pending = [(i, v) for i, v in enumerate(runs) if i not in done]
    blobs = {name: path.read_bytes() for name, path in fmus.items()}
    if results.exists() and results.stat().st_size and not results.read_bytes().endswith(b"\n"):
        with open(results, "a", encoding="utf-8") as f:
            f.write("\n")  # an interrupted write: keep its partial line apart
    with open(results, "a", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        if not done:
            writer.writeheader()
            f.flush()
        if pending:
            _run_tasks(spec, pending, blobs, writer, f, scheduler, workers, show_progress)
    write_summary(spec, results, out)
    return results


def _run_tasks(spec, pending, blobs, writer, f, scheduler, workers, show_progress) -> None:
    from dask.distributed import Client, LocalCluster, as_completed
    from tqdm import tqdm

    cluster = None
    if scheduler is None:
        cluster = LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0"
        )
        client = Client(cluster)
    else:
        try:
            client = Client(scheduler, timeout=20)
        except OSError as error:
            raise UserError(f"--scheduler {scheduler}: cannot connect ({error})") from None
    try:
        shipped = client.scatter(blobs, broadcast=True)
        futures = [client.submit(run_one, i, v, spec, shipped, pure=False) for i, v in pending]
        with tqdm(total=len(futures), unit="run", disable=not show_progress, desc=spec.name) as bar:
            for future in as_completed(futures):
                writer.writerow(future.result())
                f.flush()
                bar.update(1)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _finished_runs(results: Path, columns: Sequence[str]) -> set[int]:
    if not results.exists():
        return set()
    with open(results, newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames != list(columns):
            raise UserError(
                f"{results} was written by another spec (columns differ); choose another --out"
            )
        return {int(row["run"]) for row in reader if _complete(row)}


def _complete(row: Mapping[str, str | None]) -> bool:
    """A row written in full (an interrupted write leaves a short last line)."""
    return row.get("error") is not None and (row.get("run") or "").strip().isdigit()


def read_results(results: Path) -> list[dict[str, str]]:
    """The rows of a results CSV, one per finished run (a cut-off last line is left out)."""
    with open(results, newline="", encoding="utf-8") as f:
        return [row for row in csv.DictReader(f) if _complete(row)]


def write_summary(spec: SweepSpec, results: Path, out: Path) -> Path:
    """``summary.md`` (metric quantiles per varied parameter) and PNG plots."""
    from cosim.report import markdown_table

    rows = read_results(results)
    ok = [r for r in rows if not r["error"]]
    metrics = metric_columns(spec)
    lines = [
        f"# Sweep {spec.name}: {len(rows)} runs, {len(rows) - len(ok)} failed",
        "",
        f"Scenario `{spec.scenario}`, n = {spec.masses}, seed {spec.seed}. "
        "Quantiles 5 % / 50 % / 95 % of each metric.",
        "",
    ]
    table = []
    for metric in metrics:
        x = np.array([float(r[metric]) for r in ok if r.get(metric)])
        if x.size:
            table.append(
                ["all runs", metric, x.size, *(f"{q:.4g}" for q in np.percentile(x, [5, 50, 95]))]
            )
        for name in spec.vary:
            for label, members in _groups(ok, name):
                y = np.array([float(r[metric]) for r in members if r.get(metric)])
                if y.size:
                    table.append(
                        [
                            f"{name} {label}",
                            metric,
                            y.size,
                            *(f"{q:.4g}" for q in np.percentile(y, [5, 50, 95])),
                        ]
                    )
    lines.append(markdown_table(["runs", "metric", "count", "p5", "p50", "p95"], table))
    failures = [r for r in rows if r["error"]]
    if failures:
        lines += ["", "Failed runs:", ""] + [
            f"- run {r['run']}: {r['error']}" for r in failures[:20]
        ]
    lines += [
        "",
        *(f"![{m}]({_plot(spec, ok, m, out).name})" for m in metrics if any(r.get(m) for r in ok)),
    ]
    summary = out / "summary.md"
    summary.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return summary


def _groups(rows: list[dict[str, str]], name: str) -> list[tuple[str, list[dict[str, str]]]]:
    values = sorted({float(r[name]) for r in rows})
    if len(values) <= 8:
        return [(f"= {v:g}", [r for r in rows if float(r[name]) == v]) for v in values]
    edges = np.percentile([float(r[name]) for r in rows], [0, 25, 50, 75, 100])
    groups = []
    for lo, hi in itertools.pairwise(edges):
        members = [r for r in rows if lo <= float(r[name]) <= hi]
        groups.append((f"in [{lo:.3g}, {hi:.3g}]", members))
    return groups


def _plot(spec: SweepSpec, rows: list[dict[str, str]], metric: str, out: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(spec.vary)
    fig, axes = plt.subplots(1, 1 + len(names), figsize=(4 * (1 + len(names)), 3.4), squeeze=False)
    y = np.array([float(r[metric]) for r in rows if r.get(metric)])
    axes[0, 0].hist(y, bins=min(30, max(5, len(y) // 5)))
    axes[0, 0].set_xlabel(metric)
    axes[0, 0].set_ylabel("runs")
    for ax, name in zip(axes[0, 1:], names):
        x = np.array([float(r[name]) for r in rows if r.get(metric)])
        ax.plot(x, y, ".", alpha=0.6)
        ax.set_xlabel(name)
        ax.set_ylabel(metric)
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{spec.name}: {metric} ({len(y)} runs)")
    fig.tight_layout()
    path = out / f"{metric.replace('[', '_').replace(']', '')}.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim sweep``."""
    p = subparsers.add_parser(
        "sweep",
        help="run a parameter sweep on Dask",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("spec", type=Path, help="the sweep specification (TOML)")
    p.add_argument(
        "--scheduler", help="address of an existing Dask scheduler (default: a local cluster)"
    )
    p.add_argument(
        "--workers", type=int, default=2, help="worker processes of the local cluster (default 2)"
    )
    p.add_argument("--out", type=Path, help="output folder (default sweeps/<name>)")
    p.add_argument("--resume", action="store_true", help="finish an interrupted sweep in --out")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    spec = load_spec(args.spec)
    if args.workers < 1:
        raise UserError(f"--workers {args.workers}: at least one worker")
    out = args.out or Path("sweeps") / spec.name
    start = time.perf_counter()
    results = sweep(spec, out, args.scheduler, args.workers, args.resume, not args.no_progress)
    rows = read_results(results)
    failed = sum(1 for r in rows if r["error"])
    print(
        f"{len(rows)} runs ({failed} failed) in {time.perf_counter() - start:.1f} s; "
        f"wrote {results} and {out / 'summary.md'}"
    )
    return 0
