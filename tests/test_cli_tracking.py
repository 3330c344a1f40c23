"""``arcosim identify --set tracking=1``: the tracked chain over time written, drawn and
printed; ``--plot`` refused where there is nothing of it to draw."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from arcosim.__main__ import main
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.chain_tracker import PRIOR_STD
from arcosim.logs import write_csv


def moving_log(path: Path, seconds: float = 2.0) -> Path:
    """A log of a motor turning back and forth (not a drive's physics: the CLI's plumbing)."""
    t = np.arange(round(seconds / 1e-3) + 1) * 1e-3
    theta = np.floor((1.0 - np.cos(2.0 * t)) / (2 * np.pi / 2000)) * (2 * np.pi / 2000)
    omega = np.concatenate([[0.0], np.diff(theta) / 1e-3])
    columns = {"time": t, "i_a": 0.2 * np.sin(2.0 * t), "omega_m": omega, "theta_m": theta}
    units = {"time": "s", "i_a": "A", "omega_m": "rad/s", "theta_m": "rad"}
    return write_csv(path, columns, units=units)


def test_plot_without_tracking_is_refused(tmp_path, capsys) -> None:
    log = moving_log(tmp_path / "log.csv", 0.1)
    assert main(["identify", str(log), "--plot", str(tmp_path / "x.png")]) == 2
    assert "--set tracking=1" in capsys.readouterr().err


@pytest.mark.slow
def test_tracking_writes_draws_and_prints(build_fmus, tmp_path, capsys) -> None:
    log = moving_log(tmp_path / "log.csv")
    out, plot = tmp_path / "tracked.csv", tmp_path / "tracked.png"
    argv = ["identify", str(log), "--fmus", str(build_fmus(3)), "--set", "tracking=1"]
    assert main([*argv, "--out", str(out), "--plot", str(plot), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert set(report["tracked"]) == {
        *(f"k[{i}]" for i in (1, 2, 3)),
        *(f"B[{i}]" for i in (1, 2, 3)),
        "f_c",
        "D_m",
    }
    k1 = report["tracked"]["k[1]"]
    assert k1["commissioning"] == defaults.K
    # the prior caps σ: never less certain than the commissioning value's 10 %
    assert 0.0 < k1["std"] <= PRIOR_STD * defaults.K * (1 + 1e-9)
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 2001
    assert float(rows[0]["k[1]"]) == defaults.K  # starts at the commissioning chain
    assert {"k[1]_std", "drift_alarm", "tracking_valid"} <= set(rows[0])
    assert plot.stat().st_size > 10_000


def test_tracking_refused_outside_mode_2(build_fmus, tmp_path, capsys) -> None:
    log = moving_log(tmp_path / "log.csv", 0.1)
    argv = ["identify", str(log), "--fmus", str(build_fmus(3)), "--set", "tracking=1"]
    assert main([*argv, "--mode", "1"]) == 2
    assert "tracking = 1 needs mode = 2" in capsys.readouterr().err


@pytest.mark.parametrize("value", ["2", "-1"])
def test_tracking_takes_0_or_1(build_fmus, tmp_path, capsys, value) -> None:
    log = moving_log(tmp_path / "log.csv", 0.1)
    argv = ["identify", str(log), "--fmus", str(build_fmus(3)), "--set", f"tracking={value}"]
    assert main(argv) == 2
    assert f"parameter tracking = {value} is not allowed" in capsys.readouterr().err
