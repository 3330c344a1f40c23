"""Monte Carlo and grid sweeps of co-simulations on Dask (``arcosim sweep``).

The spec (format in :mod:`arcosim.sweeps.spec`) names the scenario, the parameters to
vary by FMU and variable (as in ``arcosim simulate``), how to draw them, the number of
runs and the metrics. Without ``--scheduler`` a ``dask.distributed.LocalCluster`` of
``--workers`` processes runs here; with it the same tasks go to that cluster. Each run
is a task that builds nothing: the FMUs are built once and shipped as bytes. Rows are
appended to ``results.csv`` as runs finish, so an interrupted sweep keeps every
finished run and ``--resume`` runs only the others; a failed run records its error and
the sweep goes on. At the end ``summary.md`` holds metric quantiles per varied
parameter and the PNGs the error histograms and the errors against each parameter
(:mod:`arcosim.sweeps.summary`).

A sweep holds its folder's lock (:func:`lock_sweep`) from the check of
``results.csv`` to the summary, so a second sweep into the same folder (fresh or
``--resume``) is refused, naming the one that runs: no run is duplicated, and two
fresh starts cannot both begin.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import datetime
import fcntl
import hashlib
import json
import os
import socket
import sys
import tempfile
import time
import traceback
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import IO

from arcosim.build.builder import ensure_built, fmu_variables
from arcosim.build.recipes import OBSERVER, PLANT
from arcosim.errors import UserError
from arcosim.experiments.metrics import flexible_score, percent_error
from arcosim.host.overrides import typed_value
from arcosim.logs import units_path
from arcosim.outputs import check_output_folder, write_text
from arcosim.sweeps.spec import SweepSpec, check_names, draw_runs, load_spec, metric_columns
from arcosim.sweeps.summary import complete, read_results, write_summary

__all__ = [
    "draw_runs",
    "load_spec",
    "lock_folder",
    "lock_sweep",
    "read_results",
    "run_one",
    "sweep",
]

#: The lock file of a sweep folder; while locked it says who holds it.
LOCK_FILE = ".arcosim-sweep.lock"
#: How long a refused sweep waits for the lock's holder to write who it is (s).
HOLDER_WAIT = 1.0
#: The files a sweep writes into its folder (besides the PNG plots).
RESULTS, SUMMARY = "results.csv", "summary.md"


@contextlib.contextmanager
def lock_sweep(out: Path) -> Iterator[None]:
    """Hold the lock of the sweep folder ``out``, or refuse naming the sweep that does.

    An ``flock`` on :data:`LOCK_FILE`, taken without waiting; the kernel releases it
    when the holder exits, however it exits, so it is never stale. The holder writes
    its pid, host, start time and command into the file for the message.

    Raises
    ------
    UserError
        When another process holds the lock, or the folder cannot be used.
    """
    with lock_folder(out):
        yield


@contextlib.contextmanager
def lock_folder(out: Path, lock_file: str = LOCK_FILE, what: str = "sweep") -> Iterator[None]:
    """Hold the lock ``lock_file`` of the folder ``out`` (one writer per folder), or refuse
    naming the process that holds it; :func:`lock_sweep`'s mechanism for any job.

    Parameters
    ----------
    out : Path
        The folder, created if missing.
    lock_file : str
        The lock file's name inside ``out``.
    what : str
        The job that writes there, for the refusal ("another sweep is writing there").

    Raises
    ------
    UserError
        When another process holds the lock, or the folder cannot be used.
    """
    check_output_folder(out)
    try:
        handle = open(out / lock_file, "a+", encoding="utf-8")  # noqa: SIM115 (held across the yield)
    except OSError as error:
        raise UserError(f"--out {out}: cannot lock the folder ({error.strerror})") from None
    with handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(handle)
            raise UserError(
                f"--out {out}: another {what} is writing there ({holder}); wait for it to "
                "finish or choose another --out"
            ) from None
        try:
            handle.seek(0)
            handle.truncate()
            started = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
            command = " ".join(["arcosim", *sys.argv[1:]])[:200]
            handle.write(
                f"pid {os.getpid()} on {socket.gethostname()}, started {started}: {command}\n"
            )
            handle.flush()
            yield
        finally:
            handle.seek(0)
            handle.truncate()
            fcntl.flock(handle, fcntl.LOCK_UN)


def _holder(handle: IO[str]) -> str:
    """Who holds the lock, as the holder wrote it in the lock file. A holder writes its
    line a moment after taking the lock, so an empty file is read again for up to
    :data:`HOLDER_WAIT` s before the holder is named "one that is starting"."""
    deadline = time.monotonic() + HOLDER_WAIT
    while True:
        handle.seek(0)
        holder = " ".join(handle.read().split())[:300]
        if holder or time.monotonic() > deadline:
            return holder or "one that is starting"
        time.sleep(0.01)


def run_one(
    run: int, values: Mapping[str, object], spec: SweepSpec, blobs: Mapping[str, bytes]
) -> dict:
    """One co-simulation (a Dask task): its row of the results.

    Parameters
    ----------
    run : int
        The run's number (an index).
    values : mapping of str to object
        Its varied values by ``"fmu.name"`` (each in the variable's unit).
    spec : SweepSpec
        The sweep.
    blobs : mapping of str to bytes
        The FMU files by name, shipped to the worker.

    Returns
    -------
    dict
        ``run``, the varied values, the metrics, ``runtime`` (s) and ``error`` (empty,
        or the failure in one line: a failed run is recorded, the sweep goes on).
    """
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
    from arcosim.experiments.scenarios import SCENARIOS, run_scenario
    from arcosim.fmu.flexchain import defaults

    settings = {**spec.fixed, **values}
    variables = fmu_variables(folder)
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
    every_step = "theta_error" in spec.metrics  # scores need the whole record
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
        record_every=1 if every_step else 10**9,
    )
    plant = typed["plant"]

    out: dict[str, float] = {}
    for metric in spec.metrics:
        if metric == "k_error":
            out[metric] = percent_error(r["observer.k_hat"][-1], plant.get("k[1]", defaults.K))
        elif metric == "B_error":
            out[metric] = percent_error(r["observer.B_hat"][-1], plant.get("B[1]", defaults.B))
        elif metric == "D_m_error":
            out[metric] = percent_error(r["observer.D_m_hat"][-1], plant.get("D_m", defaults.D_M))
        elif metric == "f_c_error":
            out[metric] = percent_error(r["observer.f_c_hat"][-1], plant.get("f_c", defaults.F_C))
        elif metric == "theta_error":
            motor = r["plant.theta_m_true"]
            for i in range(1, n + 1):
                truth = r[f"plant.theta[{i}]"]
                est = r[f"observer.theta_hat[{i}]"]
                out[f"theta_error[{i}]"] = flexible_score(est, truth, motor)
    return out


def sweep(
    spec: SweepSpec,
    out: Path,
    scheduler: str | None = None,
    workers: int = 2,
    resume: bool = False,
    show_progress: bool = True,
    fmu_dir: Path | None = None,
) -> Path:
    """Run the sweep (the module's docstring says how).

    Parameters
    ----------
    spec : SweepSpec
        The checked spec.
    out : Path
        The sweep's folder: ``results.csv``, ``summary.md`` and the PNG plots.
    scheduler : str, optional
        Address of a Dask scheduler; default: a local cluster of ``workers`` processes.
    workers : int
        Number of local worker processes (a count).
    resume : bool
        Whether to finish the sweep in ``out``, running only the runs it lacks.
    show_progress : bool
        Whether to show a progress bar.
    fmu_dir : Path, optional
        Folder of the FMUs, built there if missing or stale (default: the per-user cache).

    Returns
    -------
    Path
        The results CSV.

    Raises
    ------
    UserError
        A name or value the FMUs refuse, a results file that exists without ``resume``,
        a folder another sweep holds.

    Examples
    --------
    A two-run grid over the observer's gain; :func:`draw_runs` shows the runs the
    sweep would run:

    >>> import tempfile
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = Path(folder.name) / "gains.toml"
    >>> _ = path.write_text('''scenario = "rigid"
    ... duration = 0.5
    ... metrics = ["runtime"]
    ... [vary]
    ... "observer.g_dist" = { distribution = "grid", values = [100.0, 200.0] }
    ... ''', encoding="utf-8")
    >>> spec = load_spec(path)
    >>> draw_runs(spec)
    [{'observer.g_dist': 100.0}, {'observer.g_dist': 200.0}]

    ``sweep(spec, Path(folder.name) / spec.name, workers=1)`` then runs them (a local
    Dask cluster takes seconds to start) and returns the path of ``results.csv``, whose
    rows :func:`read_results` reads.

    >>> folder.cleanup()
    """
    folder = ensure_built(spec.masses, fmu_dir)
    fmus = {f"{r.name}.fmu": folder / f"{r.name}.fmu" for r in (PLANT, OBSERVER)}
    variables = fmu_variables(folder)
    check_names(spec, variables)
    runs = draw_runs(spec)
    columns = ["run", *spec.vary, *metric_columns(spec), "error"]
    results = out / RESULTS
    with lock_sweep(out):
        done = _finished_runs(results, columns) if resume else set()
        if results.exists() and not resume:
            raise UserError(
                f"{results} exists: add --resume to finish that sweep, or choose another --out"
            )
        write_text(
            units_path(results),
            json.dumps(result_units(spec, variables, columns), indent=1) + "\n",
            force=True,
        )
        pending = [(i, v) for i, v in enumerate(runs) if i not in done]
        blobs = {name: path.read_bytes() for name, path in fmus.items()}
        if results.exists() and _last_byte(results) not in (b"", b"\n"):
            with open(results, "a", encoding="utf-8") as f:
                f.write("\n")  # an interrupted write: keep its partial line apart
        with open(results, "a", newline="", encoding="utf-8") as f:
            writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
            if not results.stat().st_size:
                writer.writeheader()
                f.flush()
            if pending:
                _run_tasks(spec, pending, blobs, writer, f, scheduler, workers, show_progress)
        write_summary(spec, results, out)
    return results


def result_units(
    spec: SweepSpec, variables: Mapping[str, Mapping[str, object]], columns: Sequence[str]
) -> dict[str, str]:
    """The unit of each column of ``results.csv`` (its sidecar ``results.units.json``):
    a varied parameter's as its FMU declares it, ``%`` for the parameter errors, ``s``
    for the runtime, ``1`` for the run's number and the θ scores (ratios), ``""`` for
    the error message."""
    units = {"run": "1", "error": ""}
    for name in spec.vary:
        fmu, variable = name.split(".", 1)
        units[name] = getattr(variables[fmu][variable], "unit", None) or "1"
    for name in metric_columns(spec):
        units[name] = {"runtime": "s"}.get(name, "1" if name.startswith("theta_") else "%")
    return {column: units[column] for column in columns}


def _run_tasks(spec, pending, blobs, writer, f, scheduler, workers, show_progress) -> None:
    from dask.distributed import as_completed
    from tqdm import tqdm

    if show_progress:  # Dask takes seconds to start, before the bar's first run
        how = f"starting a local Dask cluster ({workers} workers)"
        if scheduler is not None:
            how = f"connecting to the Dask scheduler at {scheduler}"
        print(f"{spec.name}: {how} for {len(pending)} runs…", file=sys.stderr)
    with dask_client(scheduler, workers) as client:
        shipped = client.scatter(blobs, broadcast=True)
        futures = [client.submit(run_one, i, v, spec, shipped, pure=False) for i, v in pending]
        with tqdm(total=len(futures), unit="run", disable=not show_progress, desc=spec.name) as bar:
            for future in as_completed(futures):
                writer.writerow(future.result())
                f.flush()
                bar.update(1)


@contextlib.contextmanager
def dask_client(scheduler: str | None, workers: int) -> Iterator[object]:
    """A Dask client, closed on leaving: on a local cluster of ``workers`` processes of
    one thread each (closed too), or on the scheduler at the address ``scheduler``.

    Raises
    ------
    UserError
        When the scheduler cannot be reached, naming its address.
    """
    from dask.distributed import Client, LocalCluster

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
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _last_byte(path: Path) -> bytes:
    """The file's last byte (``b""`` for an empty file), without reading the rest."""
    with open(path, "rb") as f:
        if f.seek(0, os.SEEK_END) == 0:
            return b""
        f.seek(-1, os.SEEK_END)
        return f.read(1)


def _finished_runs(results: Path, columns: Sequence[str]) -> set[int]:
    if not results.exists():
        return set()
    try:
        with open(results, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            if reader.fieldnames != list(columns):
                raise UserError(
                    f"{results} was written by another spec (columns differ); choose another --out"
                )
            return {int(row["run"]) for row in reader if complete(row)}
    except (UnicodeDecodeError, csv.Error) as error:
        raise UserError(
            f"{results}: not a sweep's results ({error}); choose another --out"
        ) from None
