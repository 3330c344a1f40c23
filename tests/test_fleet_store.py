"""The fleet's store: a row appended durably, a torn last row ignored and cut, a crash
that loses no finished row, and a second run that identifies only the missing logs.

The rows are hand-made (the store does not care what the fit was); the end-to-end test
kills ``arcosim fleet identify`` on a tiny simulated fleet mid-run.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import arcosim
from arcosim.errors import UserError
from arcosim.fleet.store import append_store, read_store, store_path, write_store


def row(i: int, **extra) -> dict:
    """The ``i``-th hand-made row: a one-spring fit whose k[1] (N·m/rad) is ``i``."""
    base = {
        "axis": f"a{i % 3}",
        "date": f"2026-01-{1 + i % 28:02d}T{i // 28:05d}",
        "log": f"/fleet/a{i % 3}/{i}.csv",
        "status": "ok",
        "reason": "",
        "n": 1,
        "verdict": "trusted",
        "verdict_reasons": "",
        "seconds": 1.5,
        "version": "0",
        "k[1]": float(i),
        "k[1]_std": 1e-3,
    }
    return {**base, **extra}


def test_a_torn_last_row_is_ignored_then_cut_before_the_next_append(tmp_path: Path) -> None:
    append_store(tmp_path, row(0))
    append_store(tmp_path, row(1))
    path = store_path(tmp_path)
    whole = path.read_bytes()
    with open(path, "ab") as f:  # a crash in the middle of the third row's write
        f.write(b"a2,2026-01-03T00000,/fleet/a2/2.csv,o")
    assert [r["k[1]"] for r in read_store(tmp_path)] == [0.0, 1.0]
    append_store(tmp_path, row(3))
    assert [r["k[1]"] for r in read_store(tmp_path)] == [0.0, 1.0, 3.0]
    text = path.read_bytes()
    assert text.startswith(whole) and b"2.csv" not in text and text.endswith(b"\n")


def test_a_torn_row_longer_than_one_read_is_cut_whole(tmp_path: Path) -> None:
    from arcosim.fleet.store import _TAIL

    append_store(tmp_path, row(0))
    with open(store_path(tmp_path), "ab") as f:
        f.write(b"a1," + b"x" * (3 * _TAIL))  # the newline is three reads back
    append_store(tmp_path, row(1))
    assert [r["k[1]"] for r in read_store(tmp_path)] == [0.0, 1.0]
    assert b"xxx" not in store_path(tmp_path).read_bytes()


def test_a_row_with_new_columns_rewrites_the_header_and_keeps_every_row(tmp_path: Path) -> None:
    append_store(tmp_path, row(0))
    append_store(tmp_path, row(1, n=2, **{"k[2]": 7.0, "k[2]_std": 1e-3}))
    append_store(tmp_path, row(2))  # fewer columns than the header: its cells stay empty
    back = read_store(tmp_path)
    assert [r["k[1]"] for r in back] == [0.0, 1.0, 2.0] and back[1]["k[2]"] == 7.0
    assert [r["n"] for r in back] == [1, 2, 1]
    units = (tmp_path / "fleet.units.json").read_text()
    assert '"k[2]_std": "N*m/rad"' in units


def test_a_failed_rows_reason_stays_on_its_own_line(tmp_path: Path) -> None:
    failed = {"axis": "a", "date": "2026-01-01", "log": "x.csv", "status": "failed"}
    append_store(tmp_path, {**failed, "reason": "first line\nsecond line"})
    (back,) = read_store(tmp_path)
    assert back["reason"] == "first line second line" and back["n"] is None


def test_a_file_that_is_not_a_store_is_refused_not_appended_to(tmp_path: Path) -> None:
    store_path(tmp_path).write_text("time,i_a\n0,0\n")
    with pytest.raises(UserError, match="not a fleet store"):
        append_store(tmp_path, row(0))
    assert store_path(tmp_path).read_text() == "time,i_a\n0,0\n"


@pytest.mark.system
def test_a_writer_killed_mid_run_loses_no_finished_row(tmp_path: Path) -> None:
    # A process appends rows as fast as it can and is killed (SIGKILL, no clean-up) once
    # the store holds 200 rows; whatever it was writing, the store reads back as the
    # first m rows exactly, and the next append follows them.
    script = textwrap.dedent(
        f"""
        import sys
        from pathlib import Path
        sys.path.insert(0, {str(Path(__file__).parent)!r})
        from test_fleet_store import row
        from arcosim.fleet.store import append_store
        for i in range(100_000):
            append_store(Path({str(tmp_path)!r}), row(i))
        """
    )
    writer = subprocess.Popen([sys.executable, "-c", script])
    try:
        deadline = time.monotonic() + 120
        while len(read_store(tmp_path)) < 200:
            assert writer.poll() is None, "the writer ended before it was killed"
            assert time.monotonic() < deadline, "fewer than 200 rows after 120 s"
            time.sleep(0.05)
    finally:
        writer.send_signal(signal.SIGKILL)
        writer.wait(timeout=30)
    back = read_store(tmp_path)
    assert [r["k[1]"] for r in back] == [float(i) for i in range(len(back))]
    assert [r["date"] for r in back] == [row(i)["date"] for i in range(len(back))]
    append_store(tmp_path, row(len(back)))
    assert len(read_store(tmp_path)) == len(back) + 1


@pytest.mark.slow
@pytest.mark.system
@pytest.mark.skipif(not hasattr(os, "killpg"), reason="process groups (POSIX) end the workers")
def test_a_run_killed_mid_fleet_is_finished_by_the_next_run_alone(tmp_path: Path) -> None:
    from benchmarks.simulators.fleet_sample import write_fleet

    fleet, out = tmp_path / "fleet", tmp_path / "out"
    write_fleet(fleet, axes=2, seconds=5.0)  # 5 logs, one of them corrupt
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root)}
    command = [sys.executable, "-m", "arcosim", "fleet", "identify", str(fleet)]
    command += ["--out", str(out), "--workers", "1", "--no-progress"]
    run = subprocess.Popen(command, env=env, start_new_session=True)
    try:
        deadline = time.monotonic() + 300
        while len(read_store(out)) < 2:
            assert run.poll() is None, "the run ended before it was killed"
            assert time.monotonic() < deadline, "fewer than 2 rows after 300 s"
            time.sleep(0.1)
    finally:
        os.killpg(run.pid, signal.SIGKILL)  # the run and its local cluster, no clean-up
        run.wait(timeout=30)
    kept = read_store(out)
    assert 2 <= len(kept) < 5
    with open(store_path(out), "ab") as f:  # as if the kill had hit a row's write
        f.write(b"a2,2026-02-05,")
    again = arcosim.identify_fleet(fleet, out, workers=1)
    assert (again.total, again.skipped, again.identified) == (5, len(kept), 5 - len(kept))
    final = [(r["axis"], r["date"], r["status"]) for r in read_store(out)]
    assert len(set(final)) == len(final) == 5
    assert final[: len(kept)] == [(r["axis"], r["date"], r["status"]) for r in kept]


def test_write_store_still_writes_a_whole_store_at_once(tmp_path: Path) -> None:
    write_store(tmp_path, [row(0), row(1)])
    append_store(tmp_path, row(2))
    assert [r["k[1]"] for r in read_store(tmp_path)] == [0.0, 1.0, 2.0]
