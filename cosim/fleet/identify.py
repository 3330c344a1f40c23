"""Every log of a fleet identified on Dask, each result a row of the store.

:func:`identify_fleet` reads the fleet's folder (:mod:`arcosim.fleet.layout`), leaves
out the logs the store in ``out`` already holds, and sends each other log to a Dask
worker (:func:`identify_log`: the log is read there, BLAS limited to one thread). Each
result is appended to the store (:func:`arcosim.fleet.store.append_store`: one line,
synced to disk) as it arrives, so an interrupted run keeps every finished log and the
next run does only the rest. A log that cannot be read or identified is recorded as
failed with its reason in one line, and the fleet goes on. One writer per ``out``: the
run holds the folder's lock (:func:`arcosim.sweeps.runner.lock_folder`).
"""

from __future__ import annotations

import math
import time
import traceback
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TextIO

from threadpoolctl import threadpool_limits

from arcosim.errors import ArcosimError, UserError
from arcosim.fleet.layout import Axis, FleetLog, read_fleet
from arcosim.fleet.store import STD, append_store, read_store, store_path, write_store
from arcosim.sweeps.runner import dask_client, lock_folder
from arcosim.version import __version__

#: The lock file of a fleet's output folder.
LOCK_FILE = ".arcosim-fleet.lock"


@dataclass(frozen=True)
class FleetRun:
    """What one :func:`identify_fleet` did.

    Parameters
    ----------
    store : Path
        The store's file (``OUT/fleet.csv``).
    total : int
        Logs in the fleet's folder (a count).
    skipped : int
        Logs the store already held, not identified again (a count).
    rows : list of dict
        The rows this run added, one per log identified (or failed).
    seconds : float
        Wall time of the run (s).

    Examples
    --------
    >>> run = FleetRun(Path("out/fleet.csv"), 3, 2, [{"status": "failed"}], 1.0)
    >>> run.identified, run.failed
    (1, 1)
    """

    store: Path
    total: int
    skipped: int
    rows: list[dict[str, object]] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def identified(self) -> int:
        """Logs this run sent to identification, failed ones included (a count)."""
        return len(self.rows)

    @property
    def failed(self) -> int:
        """Logs this run recorded as failed (a count)."""
        return sum(1 for row in self.rows if row["status"] == "failed")


def identify_fleet(
    folder: str | Path,
    out: str | Path,
    *,
    scheduler: str | None = None,
    workers: int = 2,
    progress: TextIO | None = None,
) -> FleetRun:
    r"""Identify every log of the fleet in ``folder`` the store in ``out`` does not hold yet.

    Parameters
    ----------
    folder : str or Path
        The fleet: ``<axis>/axis.toml`` and ``<axis>/<ISO date>.csv``
        (:mod:`arcosim.fleet.layout`).
    out : str or Path
        The output folder: the store ``fleet.csv`` and its units sidecar; created if
        missing.
    scheduler : str, optional
        Address of a Dask scheduler; default: a local cluster of ``workers`` processes.
    workers : int
        Worker processes of the local cluster (a count).
    progress : file-like, optional
        Where to write a line per finished log (done/total, failures, ETA); none when
        not given.

    Returns
    -------
    FleetRun
        The store and the rows this run added.

    Raises
    ------
    UserError
        A wrong fleet folder or ``axis.toml``, a log not named by an ISO date, a store
        that is not one, an ``out`` another run holds, a scheduler that cannot be
        reached, fewer than 1 worker. A log that cannot be identified is a failed row,
        never an error.

    Examples
    --------
    An axis without logs yet (a log would be identified on Dask):

    >>> from pathlib import Path
    >>> axis = Path("fleet/a1")
    >>> axis.mkdir(parents=True)
    >>> text = "[set]\nk_to = 0.0406\nJ_mo = 2.09e-5\nencoder_cpr = 2000\n"
    >>> _ = (axis / "axis.toml").write_text(text)
    >>> run = arcosim.identify_fleet("fleet", "fleet-out", workers=1)
    >>> run.total, run.identified, run.store.name
    (0, 0, 'fleet.csv')
    """
    start = time.perf_counter()
    if scheduler is None and not (isinstance(workers, int) and workers >= 1):
        raise UserError(f"workers = {workers!r}: give a whole number of processes, 1 or more")
    folder, out = Path(folder), Path(out)
    axes, logs = read_fleet(folder, skip=out)
    with lock_folder(out, LOCK_FILE, "fleet identification"):
        rows = read_store(out)
        done = {(str(row["axis"]), Path(str(row["log"])).name) for row in rows}
        pending = [log for log in logs if (log.axis, log.path.name) not in done]
        added: list[dict[str, object]] = []
        if pending:
            _run(pending, axes, added, out, scheduler, workers, progress)
        elif not store_path(out).exists():
            write_store(out, rows)
    return FleetRun(
        store_path(out), len(logs), len(logs) - len(pending), added, time.perf_counter() - start
    )


def identify_log(path: str, axis: str, date: str, options: Mapping[str, object]) -> dict:
    """One log identified (a Dask task): its row of the store.

    Parameters
    ----------
    path : str
        The log's file, read here (on the worker).
    axis : str
        The axis's name.
    date : str
        The log's ISO date.
    options : mapping
        ``scales`` (column → factor) and :func:`arcosim.identify_drive`'s keywords
        (``k_t`` in N·m/A, ``J_m`` in kg·m², ``encoder_cpr``, …).

    Returns
    -------
    dict
        ``axis``, ``date``, ``log``, ``status`` (``"ok"`` or ``"failed"``), ``reason``
        (one line when failed), ``n``, ``verdict``, ``verdict_reasons``, every
        parameter and its ``_std``, ``seconds`` (s), ``version``.
    """
    started = time.perf_counter()
    row: dict[str, object] = {"axis": axis, "date": date, "log": path, "version": __version__}
    try:
        with threadpool_limits(limits=1, user_api="blas"):
            row.update(_identified(path, options))
        row.update(status="ok", reason="")
    except Exception as error:  # a bad log is recorded, the fleet goes on
        row.update(status="failed", reason=_reason(error))
    row["seconds"] = round(time.perf_counter() - started, 3)
    return row


def _identified(path: str, options: Mapping[str, object]) -> dict[str, object]:
    from arcosim.identification.drive_identification import identify_drive
    from arcosim.logs import read_log

    options = dict(options)
    log = read_log(path, options.pop("scales", None) or None)
    c = log.columns
    result = identify_drive(log.time, c["i_a"], c["omega_m"], c["theta_m"], **options)
    row: dict[str, object] = {
        "n": result.masses,
        "verdict": result.verdict.word,
        "verdict_reasons": " | ".join(" ".join(r.split()) for r in result.verdict.reasons),
    }
    for name, value in result.parameters.items():
        row[name] = float(value)
        row[name + STD] = float(result.std.get(name, math.nan))
    return row


def _reason(error: Exception) -> str:
    """The failure in one line: the message of an error a user can act on, and for any
    other error its type and the line of code it came from."""
    text = " | ".join(line.strip() for line in str(error).splitlines() if line.strip())
    if isinstance(error, ArcosimError):
        return text[:400]
    frames = traceback.extract_tb(error.__traceback__)
    place = f" (at {Path(frames[-1].filename).name}:{frames[-1].lineno})" if frames else ""
    return f"{type(error).__name__}: {text}{place}"[:400]


def _options(axis: Axis) -> dict[str, object]:
    return {"scales": dict(axis.scales), **axis.identify_options()}


def _run(
    pending: list[FleetLog],
    axes: Mapping[str, Axis],
    added: list[dict[str, object]],
    out: Path,
    scheduler: str | None,
    workers: int,
    progress: TextIO | None,
) -> None:
    """Send the pending logs to Dask; add each result to the store as it arrives."""
    from dask.distributed import as_completed

    _say(progress, _starting(len(pending), scheduler, workers))
    with dask_client(scheduler, workers) as client:
        futures = {
            client.submit(
                identify_log,
                str(log.path.resolve()),
                log.axis,
                log.date,
                _options(axes[log.axis]),
                pure=False,
            ): log
            for log in pending
        }
        started = time.perf_counter()
        for future in as_completed(futures):
            row = _result(future, futures[future])
            append_store(out, row)
            added.append(row)
            _say(progress, _progress_line(added, len(pending), time.perf_counter() - started))


def _result(future, log: FleetLog) -> dict[str, object]:
    """The task's row; a task Dask itself lost (a worker that died on it) is a failed row."""
    try:
        return future.result()
    except Exception as error:  # the worker, not the log's identification, failed
        return {
            "axis": log.axis,
            "date": log.date,
            "log": str(log.path.resolve()),
            "status": "failed",
            "reason": f"the Dask task failed: {_reason(error)}",
            "version": __version__,
        }


def _starting(count: int, scheduler: str | None, workers: int) -> str:
    how = f"a local Dask cluster of {workers} workers"
    if scheduler is not None:
        how = f"the Dask scheduler at {scheduler}"
    return f"fleet: {count} logs to identify on {how}…"


def _progress_line(added: list[dict[str, object]], total: int, elapsed: float) -> str:
    """``fleet: 3/8 logs, 1 failed, ETA 40 s (axis a1 2026-03-01 ok)``."""
    done = len(added)
    failed = sum(1 for row in added if row["status"] == "failed")
    eta = elapsed / done * (total - done)
    last = added[-1]
    what = f"{last['axis']} {last['date']} {last['status']}"
    if last["status"] == "ok":
        what += f", {last['verdict']}"
    return f"fleet: {done}/{total} logs, {failed} failed, ETA {eta:.0f} s ({what})"


def _say(stream: TextIO | None, line: str) -> None:
    if stream is not None:
        print(line, file=stream, flush=True)
