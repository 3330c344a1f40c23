"""``check`` and ``identify`` share one set of decisions
(:func:`arcosim.identification.checks.log_decision.decide_log`): on one seed of every log type
— the README's sample, an off-grid multi-sine, a square-wave position reference in a
position loop, a PRBS (the log generators of ``benchmarks/excitation_accuracy.py``), a
3 s record, the time in ms, the current in A read with ``--scale i_a=0.001`` — ``check``
exits 1 exactly when ``identify --method whole-chain`` refuses, and every
warning ``check`` prints, ``identify`` prints too (among its warnings, or in its
refusal). A log ``check`` doubts (exit 3: implausible units or length, an excitation
above the band) gives an untrusted fit (exit 3) if ``identify`` fits it at all. Each case
runs both commands as a user would: slow."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from arcosim.cli import main
from arcosim.logs import write_csv

SAMPLE = Path(__file__).parents[1] / "examples" / "data" / "belt_drive.csv"
COUNT = "0.0031415926535897933"
README = ["--scale", "i_a=0.001", "--scale", f"theta_m={COUNT}", "--scale", f"omega_m={COUNT}"]
MOTOR = ["--set", "k_to=0.0406", "--set", "J_mo=2.09e-5", "--set", "encoder_cpr=2000"]


def _simulated(tmp_path: Path, name: str) -> tuple[Path, list[str]]:
    """One seed of an excitation row's log (10 s), written as a CSV in SI units."""
    from benchmarks import excitation_accuracy

    log = excitation_accuracy.ROWS[name].log(1, 10.0)
    path = tmp_path / "log.csv"
    columns = {"time": log.time, "i_a": log.i_a, "omega_m": log.omega_m, "theta_m": log.theta_m}
    write_csv(path, columns)
    return path, []


def _sample(tmp_path: Path, rows: int | None, scales: list[str]) -> tuple[Path, list[str]]:
    """The README's sample (its first ``rows`` rows) with the README's scales and
    ``scales`` after them (a later ``--scale`` of a column wins)."""
    if rows is None:
        return SAMPLE, [*README, *scales]
    path = tmp_path / "short.csv"
    lines = SAMPLE.read_text().splitlines()[: rows + 1]
    path.write_text("\n".join(lines) + "\n")
    return path, [*README, *scales]


CASES = {
    "README sample": lambda p: _sample(p, None, []),
    "off-grid multi-sine": lambda p: _simulated(p, "off-grid multi-sine"),
    "square wave, position loop": lambda p: _simulated(p, "square wave, position loop"),
    "PRBS": lambda p: _simulated(p, "PRBS"),
    "3 s record": lambda p: _sample(p, 3000, []),
    "time in ms": lambda p: _sample(p, None, ["--scale", "time=1000"]),
    "current in A, --scale i_a=0.001": lambda p: _sample(p, None, ["--scale", "i_a=1e-6"]),
}


@pytest.mark.slow
@pytest.mark.parametrize("case", list(CASES))
def test_check_agrees_with_identify(case: str, tmp_path: Path, capsys) -> None:
    log, scales = CASES[case](tmp_path)
    capsys.readouterr()
    checked = main(["check", str(log), *scales, *MOTOR, "--json"])
    report = json.loads(capsys.readouterr().out)
    fitted = main(
        [
            "identify",
            str(log),
            *scales,
            *MOTOR,
            "--method",
            "whole-chain",
            "--masses",
            "auto",
            "--json",
        ]
    )
    out, err = capsys.readouterr()
    assert checked in (0, 1, 3) and fitted in (0, 1, 3), (checked, fitted, err)
    assert (checked == 1) == (fitted == 1), (case, report["problems"], err)
    if checked == 3:  # what check doubts, the fit's verdict names
        assert fitted == 3 and set(report["doubts"]) <= set(json.loads(out)["reasons"])
    said = json.loads(out)["warnings"] if fitted != 1 else [err]
    missing = [w for w in report["warnings"] if not any(w in text for text in said)]
    assert not missing, (case, missing, said)
    assert not any("sample faster" in p or "extend the lines" in p for p in report["problems"])
    if case == "square wave, position loop":
        assert report["excitation"].startswith("periodic"), report["excitation"]
    if case == "PRBS":
        assert report["excitation"].startswith("broadband"), report["excitation"]
    assert np.isfinite(report["band"])


@pytest.mark.slow
def test_a_prbs_log_of_a_drive_without_a_mode_above_the_band_is_trusted(tmp_path: Path, capsys):
    """The excitation row's PRBS log (its drive's modes all below 3·g_dist = 300 rad/s):
    the fit is right (n and J_i, k_i, see bench accuracy), so its verdict should be too."""
    log, _ = _simulated(tmp_path, "PRBS")
    capsys.readouterr()
    args = ["identify", str(log), *MOTOR, "--method", "whole-chain", "--masses", "auto"]
    fitted = main([*args, "--json"])
    report = json.loads(capsys.readouterr().out)
    assert fitted == 0 and report["verdict"] == "trusted", report["reasons"]
