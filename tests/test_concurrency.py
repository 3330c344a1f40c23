"""Builds and sweeps are safe to run twice at once.

Two ``arcosim build`` into one folder with an ``arcosim simulate`` of that folder
beside them: every process succeeds and every FMU afterwards is complete and
current. Two sweeps into one folder: the second is refused naming the first (pid,
start time), and the results hold every run once. ``ARCOSIM_STRESS_ROUNDS`` repeats
the build trial (default 1 round here; the report's figures come from more).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from arcosim.cli import main

SPEC = """
name = "race"
scenario = "selfid"
duration = {duration}
runs = {runs}
seed = 5
metrics = ["D_m_error"]
[vary]
"observer.g_dist" = {{ distribution = "uniform", low = 100.0, high = 200.0 }}
"""


def arcosim(*args: object) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "arcosim", *map(str, args)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def finish(process: subprocess.Popen, timeout: float = 600) -> tuple[int, str, str]:
    out, err = process.communicate(timeout=timeout)
    return process.returncode, out, err


@pytest.mark.system
@pytest.mark.slow
def test_two_builds_and_a_simulation_in_one_folder(tmp_path: Path) -> None:
    from arcosim.build.cache import fmu_problem, is_current
    from arcosim.build.recipes import RECIPES, SSP_NAME

    folder = tmp_path / "fmus"
    rounds = int(os.environ.get("ARCOSIM_STRESS_ROUNDS", "1"))
    for trial in range(rounds):
        builds = [arcosim("build", "--masses", 1, "--out", folder) for _ in range(2)]
        time.sleep(0.5 * (trial % 3))  # the simulation starts before, during or between
        simulation = arcosim(
            "simulate", "--masses", 1, "--fmus", folder, "--duration", 0.2, "--json"
        )
        for process in (*builds, simulation):
            code, _, err = finish(process)
            assert code == 0, f"trial {trial}: {process.args[3]} exited {code}: {err[-2000:]}"
            assert "Traceback" not in err
        files = [folder / r.file_name for r in RECIPES] + [folder / SSP_NAME]
        assert [fmu_problem(f) for f in files] == [None] * len(files), f"trial {trial}"
        assert is_current(folder, 1), f"trial {trial}"
        leftovers = [p.name for p in folder.iterdir() if p.name.endswith(".part")]
        assert not leftovers, f"trial {trial}: {leftovers}"


def test_a_second_sweep_into_a_locked_folder_is_refused_naming_the_first(
    build_fmus, tmp_path: Path, capsys
) -> None:
    from arcosim.sweeps.runner import lock_sweep

    build_fmus(3)
    spec = tmp_path / "spec.toml"
    spec.write_text(SPEC.format(duration=0.2, runs=2))
    out = tmp_path / "out"
    with lock_sweep(out):
        for resume in ([], ["--resume"]):
            code = main(["sweep", str(spec), "--out", str(out), "--no-progress", *resume])
            err = capsys.readouterr().err
            assert code == 2
            assert f"another sweep is writing there (pid {os.getpid()} on " in err
            assert "started 20" in err and len(err.strip().splitlines()) == 1
    assert not (out / "results.csv").exists()


def test_a_refusal_names_a_holder_that_has_just_taken_the_lock(tmp_path: Path) -> None:
    """A sweep that takes the lock writes who it is a moment later; one refused in that
    moment waits for the line instead of naming "one that is starting" (the two fresh
    sweeps below met that window on a loaded CI machine)."""
    import fcntl
    import threading

    from arcosim.errors import UserError
    from arcosim.sweeps.runner import LOCK_FILE, lock_sweep

    out = tmp_path / "out"
    out.mkdir()
    with open(out / LOCK_FILE, "a+", encoding="utf-8") as held:
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)  # taken, nothing written yet

        def introduce() -> None:
            held.write("pid 1 on bench, started 2026-12-02T17:50:00+00:00: arcosim sweep\n")
            held.flush()

        timer = threading.Timer(0.2, introduce)
        timer.start()
        try:
            refused = pytest.raises(UserError, match=r"another sweep is writing there \(pid 1 on")
            with refused, lock_sweep(out):
                pass
        finally:
            timer.join()


@pytest.mark.system
@pytest.mark.slow
def test_two_sweeps_into_one_folder_run_every_run_once(build_fmus, tmp_path: Path) -> None:
    """Two fresh starts at once and a --resume while they run: one sweep runs, the
    others are refused naming it, and every run is in the results once. The holder is
    stopped (SIGSTOP) while the --resume runs, so that it cannot finish first: a --resume
    started under load (about 2 s of imports when idle) found a holder of a few seconds
    finished and exited 0, and a longer sweep (six runs of 60 s, about 10 s) only
    narrowed that race."""
    from arcosim.sweeps.summary import read_results

    build_fmus(3)
    spec = tmp_path / "spec.toml"
    runs = 6
    spec.write_text(SPEC.format(duration=1.0, runs=runs))
    out = tmp_path / "out"
    lock = out / ".arcosim-sweep.lock"
    fresh = [arcosim("sweep", spec, "--out", out, "--workers", 1, "--no-progress") for _ in "ab"]
    deadline = time.monotonic() + 120
    while not (lock.exists() and lock.read_text().strip()):  # one of them holds the folder
        assert time.monotonic() < deadline, [p.poll() for p in fresh]
        time.sleep(0.05)
    holder = int(lock.read_text().split()[1])
    os.kill(holder, signal.SIGSTOP)  # alive and holding the lock, but not finishing
    try:
        resume = arcosim("sweep", spec, "--out", out, "--workers", 1, "--resume", "--no-progress")
        results = {resume.pid: finish(resume)}
    finally:
        os.kill(holder, signal.SIGCONT)
    results.update({p.pid: finish(p) for p in fresh})
    assert results[holder][0] == 0, results[holder][2]
    for pid, (code, _, err) in results.items():
        if pid != holder:
            assert code == 2, err
            assert f"another sweep is writing there (pid {holder} on " in err, err
            assert len(err.strip().splitlines()) == 1
    done = sorted(int(r["run"]) for r in read_results(out / "results.csv"))
    assert done == list(range(runs))
    assert f"{runs} runs, 0 failed" in (out / "summary.md").read_text()
    code, _, err = finish(arcosim("sweep", spec, "--out", out, "--resume", "--no-progress"))
    assert code == 0, err  # after it: nothing left to run, nothing added
    assert len(read_results(out / "results.csv")) == runs
