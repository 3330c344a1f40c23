"""The fleet: logs of many axes identified on Dask into a store, and the drift rule.

The rule's tests use hand-made rows (fast): an alarm needs both the relative threshold
and 3 standard errors of the difference; an untrusted fit is never the baseline; a
different n is a structure alarm. The end-to-end test identifies a tiny fleet simulated
by the independent simulator (:mod:`benchmarks.simulators.fleet_sample`) on a one-worker cluster;
another identifies it on a scheduler and two workers started apart (``dask scheduler``,
``dask worker``), as a user's own cluster, and finds the local cluster's store.
"""

from __future__ import annotations

import io
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import arcosim
from arcosim.cli import main
from arcosim.errors import UserError
from arcosim.fleet.drift import drift_of
from arcosim.fleet.layout import log_date, read_fleet
from arcosim.fleet.store import parameter_names, read_store, write_store

K1 = 0.3  # N·m/rad


def fit(axis: str, date: str, k1: float, std: float, *, verdict="trusted", n=1, **extra) -> dict:
    """A store row of an ok fit with one spring ``k[1]`` (N·m/rad) and J[1] fixed."""
    row = {
        "axis": axis,
        "date": date,
        "log": f"/fleet/{axis}/{date}.csv",
        "status": "ok",
        "reason": "",
        "n": n,
        "verdict": verdict,
        "verdict_reasons": "" if verdict == "trusted" else "residual above the noise floor",
        "seconds": 1.0,
        "version": "0",
        "J[1]": 4e-4,
        "J[1]_std": 1e-7,
        "k[1]": k1,
        "k[1]_std": std,
    }
    return {**row, **extra}


def test_an_alarm_needs_both_the_threshold_and_three_sigmas() -> None:
    rows = [
        fit("big_resolved", "2026-01-01", K1, 1e-3),
        fit("big_resolved", "2026-02-01", K1 * 0.88, 1e-3),
        fit("big_unresolved", "2026-01-01", K1, 0.01),  # -12 % is 2.5 sigma of the difference
        fit("big_unresolved", "2026-02-01", K1 * 0.88, 0.01),
        fit("small_resolved", "2026-01-01", K1, 1e-4),  # -3 % is 64 sigma, under 5 %
        fit("small_resolved", "2026-02-01", K1 * 0.97, 1e-4),
    ]
    report = drift_of(rows, threshold=0.05)
    (alarm,) = report.axes["big_resolved"].alarms
    assert alarm["parameter"] == "k[1]"
    assert alarm["change"] == pytest.approx(-0.12)
    assert alarm["sigmas"] == pytest.approx(-0.036 / math.hypot(1e-3, 1e-3))
    assert not report.axes["big_unresolved"].alarms
    assert not report.axes["small_resolved"].alarms
    assert report.alarmed
    assert not drift_of(rows[2:], threshold=0.05).alarmed


def test_an_untrusted_or_failed_fit_is_never_the_baseline_nor_the_latest() -> None:
    failed = {**fit("a", "2026-01-01", math.nan, math.nan), "status": "failed", "n": None}
    failed.update(reason="time does not increase at row 7", verdict="")
    rows = [
        failed,
        fit("a", "2026-01-02", K1 * 2, 1e-3, verdict="untrusted"),
        fit("a", "2026-01-03", K1, 1e-3),
        fit("a", "2026-02-01", K1 * 0.5, 1e-3, verdict="untrusted"),
        fit("a", "2026-03-01", K1 * 1.01, 1e-3),
    ]
    drift = drift_of(rows).axes["a"]
    assert drift.baseline["date"] == "2026-01-03" and drift.latest["date"] == "2026-03-01"
    assert not drift.alarms
    assert [u["date"] for u in drift.untrusted] == ["2026-01-02", "2026-02-01"]
    assert drift_of(rows).failed == [
        {"log": failed["log"], "axis": "a", "date": "2026-01-01", "reason": failed["reason"]}
    ]
    only_untrusted = drift_of(rows[:2]).axes["a"]
    assert only_untrusted.baseline is None and not only_untrusted.alarms


def test_a_baseline_date_takes_the_first_trusted_fit_from_that_date() -> None:
    rows = [fit("a", d, k, 1e-3) for d, k in [("2026-01-01", K1), ("2026-02-01", 0.8 * K1)]]
    rows.append(fit("a", "2026-03-01", 0.8 * K1, 1e-3))
    assert drift_of(rows).alarmed
    assert not drift_of(rows, baseline="2026-02-01").alarmed


def test_a_different_number_of_masses_is_a_structure_alarm() -> None:
    rows = [fit("a", "2026-01-01", K1, 1e-3), fit("a", "2026-02-01", K1, 1e-3, n=2)]
    (alarm,) = drift_of(rows).axes["a"].alarms
    assert alarm["kind"] == "structure" and (alarm["baseline"], alarm["latest"]) == (1, 2)


def test_a_parameter_the_latest_fit_does_not_hold_is_not_compared() -> None:
    base = fit("a", "2026-01-01", K1, 1e-3, D_m=2e-5, D_m_std=1e-6)
    last = fit("a", "2026-02-01", K1, 1e-3, D_m=math.nan, D_m_std=math.nan)  # D_m not fitted
    drift = drift_of([base, last]).axes["a"]
    assert [c["parameter"] for c in drift.changes] == ["J[1]", "k[1]"]
    assert "nan" not in drift_of([base, last]).text()


def test_the_report_as_json_and_text() -> None:
    rows = [fit("a", "2026-01-01", K1, 1e-3), fit("a", "2026-02-01", 0.88 * K1, 1e-3)]
    report = drift_of(rows)
    data = json.loads(report.to_json())
    (alarm,) = data["axes"]["a"]["alarms"]
    assert alarm["parameter"] == "k[1]" and alarm["change"] == pytest.approx(-0.12)
    assert len(data["axes"]["a"]["history"]) == 2 and data["failed"] == []
    assert "ALARM a: k[1] -12.0%" in report.text()


def test_the_store_reads_back_what_it_wrote(tmp_path: Path) -> None:
    rows = [fit("a", "2026-01-01", K1, 1e-3), fit("b", "2026-01-01", K1, 1e-3, **{"k[2]": 1.0})]
    write_store(tmp_path, rows)
    back = read_store(tmp_path)
    assert back[0]["k[1]"] == K1 and math.isnan(back[0]["k[2]"]) and back[1]["k[2]"] == 1.0
    assert back[0]["n"] == 1 and back[0]["verdict"] == "trusted"
    assert json.loads((tmp_path / "fleet.units.json").read_text())["k[1]_std"] == "N*m/rad"


def test_a_log_not_named_by_an_iso_date_is_refused_naming_it(tmp_path: Path) -> None:
    assert log_date(Path("2026-03-01T08-30.csv")) == "2026-03-01T08:30:00"
    axis = tmp_path / "fleet" / "a1"
    axis.mkdir(parents=True)
    (axis / "axis.toml").write_text("[set]\nk_to = 0.04\nJ_mo = 2e-5\nencoder_cpr = 2000\n")
    (axis / "monday.csv").write_text("time,i_a,omega_m,theta_m\n")
    with pytest.raises(UserError, match=r"monday\.csv: the log's name is not an ISO date"):
        read_fleet(tmp_path / "fleet")
    (axis / "monday.csv").unlink()
    (axis / "axis.toml").write_text("[set]\nk_to = 0.04\nJ_mo = 2e-5\n")
    with pytest.raises(UserError, match=r"axis\.toml: \[set\] has no encoder_cpr"):
        read_fleet(tmp_path / "fleet")


def test_drift_refuses_a_folder_without_a_store_with_one_line(tmp_path: Path, capsys) -> None:
    assert main(["fleet", "drift", str(tmp_path)]) == 2
    assert "run `arcosim fleet identify` first" in capsys.readouterr().err


def test_the_fleet_benchmark_scores_alarms_by_axis_parameter_and_sign() -> None:
    from benchmarks.fleet_accuracy import expected_alarms, found_alarms

    rows = [
        fit("k-drop", "2026-01-05", K1, 1e-3),
        fit("k-drop", "2026-03-05", 0.88 * K1, 1e-3),
        fit("two", "2026-01-05", K1, 1e-3),
        fit("two", "2026-03-05", 1.2 * K1, 1e-3),  # a false alarm, up
        fit("three", "2026-01-05", K1, 1e-3),
        fit("three", "2026-03-05", K1, 1e-3, n=2),  # a structure alarm
    ]
    found = found_alarms(drift_of(rows))
    assert found == {("k-drop", "k[1]", -1), ("two", "k[1]", 1), ("three", "n", 1)}
    assert expected_alarms() == {("k-drop", "k[1]", -1), ("friction-rise", "f_c", 1)}


# -- end to end: a tiny simulated fleet on one Dask worker ---------------------------------


@pytest.mark.slow
@pytest.mark.system
def test_a_simulated_fleet_alarms_on_the_changed_spring_only(tmp_path: Path) -> None:
    from dask.distributed import LocalCluster

    from benchmarks.simulators.fleet_sample import write_fleet, write_log

    fleet, out = tmp_path / "fleet", tmp_path / "out"
    write_fleet(fleet, axes=2, seconds=7.0)  # a1: k[1] -12 % on 2026-02-05; a2: a corrupt log
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as c:
        progress = io.StringIO()
        first = arcosim.identify_fleet(fleet, out, scheduler=c.scheduler_address, progress=progress)
        assert (first.total, first.skipped, first.identified, first.failed) == (5, 0, 5, 1)
        assert "5/5 logs, 1 failed, ETA 0 s" in progress.getvalue()

        rows = {(r["axis"], r["date"]): r for r in read_store(out)}
        corrupt = rows[("a2", "2026-01-20")]
        assert corrupt["status"] == "failed"
        assert "row 3, column i_a: 'x' is not a number" in corrupt["reason"]
        assert all(r["verdict"] == "trusted" for k, r in rows.items() if k != ("a2", "2026-01-20"))

        report = arcosim.fleet_drift(out)
        assert [a["parameter"] for a in report.axes["a1"].alarms] == ["k[1]"]
        assert report.axes["a1"].alarms[0]["change"] == pytest.approx(-0.12, abs=0.01)
        assert not report.axes["a2"].alarms
        assert [f["log"] for f in report.failed] == [corrupt["log"]]

        again = arcosim.identify_fleet(fleet, out, scheduler=c.scheduler_address)
        assert (again.skipped, again.identified) == (5, 0)

        write_log(fleet / "a2" / "2026-03-05.csv", K1, seed=3, seconds=7.0)
        new = arcosim.identify_fleet(fleet, out, scheduler=c.scheduler_address)
        assert [(r["axis"], r["date"]) for r in new.rows] == [("a2", "2026-03-05")]
        assert len(read_store(out)) == 6

    assert main(["fleet", "drift", str(out)]) == 1
    assert main(["fleet", "drift", str(out), "--json", "--threshold", "0.2"]) == 0
    assert np.isfinite(read_store(out)[0]["k[1]_std"])


def test_a_second_run_into_a_held_folder_is_refused_naming_the_first(tmp_path: Path) -> None:
    from arcosim.fleet.identify import LOCK_FILE
    from arcosim.sweeps.runner import lock_folder

    axis = tmp_path / "fleet" / "a1"
    axis.mkdir(parents=True)
    (axis / "axis.toml").write_text("[set]\nk_to = 0.04\nJ_mo = 2e-5\nencoder_cpr = 2000\n")
    with (
        lock_folder(tmp_path / "out", LOCK_FILE, "fleet identification"),
        pytest.raises(UserError, match=r"another fleet identification is writing there \(pid"),
    ):
        arcosim.identify_fleet(tmp_path / "fleet", tmp_path / "out")


def test_identify_refuses_a_wrong_axis_file_with_one_line(tmp_path: Path, capsys) -> None:
    axis = tmp_path / "fleet" / "a1"
    axis.mkdir(parents=True)
    (axis / "axis.toml").write_text(
        "masses = 2\n[set]\nk_to = 0.04\nJ_mo = -2e-5\nencoder_cpr = 9\n"
    )
    out = str(tmp_path / "out")
    assert main(["fleet", "identify", str(tmp_path / "fleet"), "--out", out]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "[set] J_mo = -2e-05: a finite number > 0" in err
    assert main(["fleet", "identify", str(tmp_path / "fleet")]) == 2  # --out is required
    both = ["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"]  # 2 is the default, given
    assert main(["fleet", "identify", str(tmp_path / "fleet"), "--out", out, *both]) == 2
    assert "--scheduler: not allowed with argument --workers" in capsys.readouterr().err


def test_a_log_too_short_or_missing_is_a_failed_row_with_its_reason(tmp_path: Path) -> None:
    from arcosim.fleet.identify import identify_log

    short = tmp_path / "2026-01-01.csv"
    short.write_text("time,i_a,omega_m,theta_m\n0,0,0,0\n0.001,0.1,0,0\n0.002,0.2,0,0\n")
    options = {"k_t": 0.0406, "J_m": 2.09e-5, "encoder_cpr": 2000}
    row = identify_log(str(short), "a1", "2026-01-01", options)
    assert row["status"] == "failed" and "at least 16 samples" in row["reason"]
    assert "\n" not in row["reason"] and row["axis"] == "a1" and row["seconds"] >= 0
    gone = identify_log(str(tmp_path / "gone.csv"), "a1", "2026-01-02", options)
    assert gone["status"] == "failed" and gone["reason"].endswith("gone.csv: no such file")


def test_an_output_folder_inside_the_fleet_is_not_an_axis(tmp_path: Path) -> None:
    axis = tmp_path / "fleet" / "a1"
    axis.mkdir(parents=True)
    (axis / "axis.toml").write_text("[set]\nk_to = 0.04\nJ_mo = 2e-5\nencoder_cpr = 2000\n")
    run = arcosim.identify_fleet(tmp_path / "fleet", tmp_path / "fleet" / "out")
    assert (run.total, run.identified) == (0, 0) and run.store.exists()
    assert arcosim.identify_fleet(tmp_path / "fleet", tmp_path / "fleet" / "out").total == 0
    with pytest.raises(UserError, match="workers = 0: give a whole number of processes"):
        arcosim.identify_fleet(tmp_path / "fleet", tmp_path / "out", workers=0)


# -- a scheduler and workers started apart, as a cluster of one's own ---------------------


def _start(command: list[str], env: dict[str, str], log: Path) -> subprocess.Popen:
    """A Dask process of the test's own, in its own process group (its children with it)."""
    with open(log, "w") as out:
        return subprocess.Popen(
            command, stdout=out, stderr=subprocess.STDOUT, env=env, start_new_session=True
        )


def _stop(process: subprocess.Popen) -> None:
    """End a process :func:`_start` started and its children: SIGTERM, then SIGKILL."""
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGTERM)
    try:
        process.wait(timeout=20)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait(timeout=10)


def _same_stores(one: list[dict], other: list[dict]) -> None:
    """The rows of two stores agree: logs, status, reason, n, verdict, parameters to 1e-9."""
    first = {(r["axis"], r["date"]): r for r in one}
    second = {(r["axis"], r["date"]): r for r in other}
    assert sorted(first) == sorted(second)
    for key, a in first.items():
        b = second[key]
        for column in ("log", "status", "reason", "n", "verdict", "verdict_reasons"):
            assert a[column] == b[column], (key, column)
        assert parameter_names(a) == parameter_names(b), key
        for name in parameter_names(a):
            assert b[name] == pytest.approx(a[name], rel=1e-9), (key, name)
            std_a, std_b = a[name + "_std"], b[name + "_std"]
            assert (math.isnan(std_a) and math.isnan(std_b)) or std_b == pytest.approx(
                std_a, rel=1e-9
            ), (key, name + "_std")


@pytest.mark.slow
@pytest.mark.system
@pytest.mark.skipif(not hasattr(os, "killpg"), reason="process groups (POSIX) end the workers")
def test_a_scheduler_started_apart_gives_the_store_of_a_local_cluster(tmp_path: Path) -> None:
    from dask.distributed import Client

    from benchmarks.simulators.fleet_sample import write_fleet

    fleet = tmp_path / "fleet"
    write_fleet(fleet, axes=2, seconds=5.0)  # 2 axes x 2 dates, and a corrupt log on a2
    local = arcosim.identify_fleet(fleet, tmp_path / "local", workers=1)
    assert (local.total, local.failed) == (5, 1)

    root = Path(__file__).resolve().parents[1]
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")])),
    }
    address_file = tmp_path / "scheduler.json"
    scheduler = [sys.executable, "-m", "distributed.cli.dask_scheduler", "--port", "0"]
    scheduler += ["--dashboard-address", ":0", "--scheduler-file", str(address_file)]
    worker = [sys.executable, "-m", "distributed.cli.dask_worker", "--nworkers", "1"]
    worker += ["--nthreads", "1", "--no-dashboard", "--scheduler-file", str(address_file)]
    processes: list[subprocess.Popen] = []
    try:
        processes.append(_start(scheduler, env, tmp_path / "scheduler.log"))
        deadline = time.monotonic() + 60
        while not address_file.exists() or not address_file.read_text().strip():
            assert processes[0].poll() is None, (tmp_path / "scheduler.log").read_text()
            assert time.monotonic() < deadline, "no scheduler file after 60 s"
            time.sleep(0.2)
        time.sleep(0.2)  # the file is written whole, once; let the write end
        address = json.loads(address_file.read_text())["address"]
        for i in (1, 2):
            processes.append(_start(worker, env, tmp_path / f"worker{i}.log"))
        with Client(address, timeout=30) as client:
            client.wait_for_workers(2, timeout=90)
        apart = arcosim.identify_fleet(fleet, tmp_path / "apart", scheduler=address)
    finally:
        for process in reversed(processes):
            _stop(process)
    assert (apart.total, apart.identified, apart.failed) == (5, 5, 1)
    _same_stores(read_store(tmp_path / "local"), read_store(tmp_path / "apart"))
