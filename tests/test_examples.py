"""The examples run as a user runs them, and say what they should."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.system
@pytest.mark.slow
def test_identify_your_drive_finds_the_belt_drive(build_fmus, tmp_path) -> None:
    """The sample log (a belt drive of benchmarks/sample_log.py: J 3e-4, 9e-4 kg·m²,
    k 0.45, 0.3 N·m/rad) identified from the motor alone, then its load angles."""
    build_fmus(2)  # the example's observer, in the session cache
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "identify_your_drive.py")],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "ARCOSIM_EXAMPLE_OUT": str(tmp_path)},
    )
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "ok: the log can support identification" in out
    assert "identified 2 load masses" in out
    values = {
        line.split()[0]: float(line.split()[1])
        for line in out.splitlines()
        if line.strip().startswith(("J[", "k["))
    }
    truth = {"J[1]": 3e-4, "J[2]": 9e-4, "k[1]": 0.45, "k[2]": 0.3}
    for name, true in truth.items():
        assert abs(values[name] / true - 1.0) < 0.01, (name, values[name])  # measured ≤ 0.05 %
    scores = [
        float(line.split()[-2]) for line in out.splitlines() if line.strip().startswith("mass ")
    ]
    assert len(scores) == 2 and max(scores) < 5.0  # % of the flexible motion; measured 0.6 %
    assert (tmp_path / "belt_drive_estimate.csv").stat().st_size > 100_000


@pytest.mark.slow
def test_the_sample_log_is_what_its_script_writes(tmp_path) -> None:
    """``python -m benchmarks.sample_log`` regenerates examples/data/belt_drive.csv: the
    same times and, within one step's rounding, the same current (0.01 mA, as written),
    counts (± 1) and true angles (7 digits as written)."""
    from benchmarks import sample_log

    out = tmp_path / "belt_drive.csv"
    sample_log.main(out)
    fresh = np.loadtxt(out, delimiter=",", skiprows=1)
    shipped = np.loadtxt(EXAMPLES / "data" / "belt_drive.csv", delimiter=",", skiprows=1)
    assert fresh.shape == shipped.shape
    np.testing.assert_array_equal(fresh[:, 0], shipped[:, 0])
    assert np.max(np.abs(fresh[:, 1] - shipped[:, 1])) <= 0.0100001  # mA
    assert np.max(np.abs(fresh[:, 3] - shipped[:, 3])) <= 1  # counts
    np.testing.assert_allclose(fresh[:, 4:], shipped[:, 4:], rtol=1e-6, atol=1e-9)  # rad


@pytest.mark.system
@pytest.mark.slow
def test_the_fmpy_example_estimates_the_reaction_torque(build_fmus, tmp_path) -> None:
    """The plant FMU drives the observer FMU in plain fmpy (the FMU page shows the same
    code): after the DOB settles, tau_reac_hat follows tau_reac to well within the
    torque itself (measured 13 % rms: the encoder's counts and the current noise through
    the DOB at g_dist = 100 rad/s; a sign or wiring error gives over 100 %)."""
    build_fmus(3)
    code = (EXAMPLES / "fmpy_plant_observer.py").read_text(encoding="utf-8")
    page = (EXAMPLES.parent / "docs" / "fmus" / "observer.md").read_text(encoding="utf-8")
    assert code[code.index("import numpy") :].rstrip() in page  # the page shows this code
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "fmpy_plant_observer.py")],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    error, torque = (float(x) for x in re.findall(r"([0-9.]+e[-+][0-9]+) N\.m", result.stdout))
    assert error < 0.3 * torque, result.stdout


@pytest.mark.system
@pytest.mark.slow
def test_the_fleet_example_alarms_on_the_slack_belt_alone(tmp_path) -> None:
    """Three conveyors of the example's own simulator, k[1] 12 % lower on conveyor-2 by
    the last date: one alarm, that one, with its sign and size (the fits resolve k[1] to
    about 0.1 %, so 1 % is far outside their spread), and the figures it draws."""
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "monitor_a_fleet.py")],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "ARCOSIM_EXAMPLE_OUT": str(tmp_path)},
    )
    assert result.returncode == 0, result.stderr
    alarms = [line for line in result.stdout.splitlines() if line.startswith("ALARM")]
    assert len(alarms) == 1 and alarms[0].startswith("ALARM conveyor-2: k[1] -")
    change = float(re.search(r"k\[1\] ([-+0-9.]+)%", alarms[0]).group(1))
    assert abs(change - -12.0) < 1.0
    assert "identified 9 logs (0 failed)" in result.stdout
    figures = tmp_path / "fleet-example" / "figures"
    assert sorted(p.name for p in figures.iterdir()) == ["axis-conveyor-2.png", "overview.png"]
