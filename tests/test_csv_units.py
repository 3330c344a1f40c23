"""Outputs for other tools: every CSV has its units beside it, and names other
tools keep on request; the files read back either way, old files too."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from arcosim.chainfile import read_chain
from arcosim.cli import main
from arcosim.fmu.flexchain.chain import Chain
from arcosim.logs import (
    DriveLog,
    read_log,
    read_units,
    tool_keys,
    tool_name,
    units_path,
    write_csv,
)

T = np.arange(5) * 1e-3
LOG = {"time": T, "i_a": 0.1 + T, "omega_m": 2.0 * T, "theta_m": T**2}


def test_tool_names_keep_letters_digits_and_underscores() -> None:
    assert tool_name("theta_hat[1]") == "theta_hat_1"
    assert tool_name("plant.i_noise_std") == "plant_i_noise_std"
    assert tool_name("observer.theta_hat[12]") == "observer_theta_hat_12"
    assert tool_name("1st") == "x1st" and tool_name("time") == "time"
    report = {"J[1]": 1.0, "std": {"k[2]": 0.1}, "runs": [{"B[1]": 2.0}]}
    assert tool_keys(report) == {"J_1": 1.0, "std": {"k_2": 0.1}, "runs": [{"B_1": 2.0}]}


def test_every_csv_has_its_units_beside_it(tmp_path: Path) -> None:
    path = tmp_path / "run.csv"
    columns = {**LOG, "plant.theta[1]": T, "observer.tau_reac_hat": T, "observer.mode": T}
    units = {"plant.theta[1]": "rad", "observer.mode": "1"}
    write_csv(path, columns, units=units)
    assert units_path(path) == tmp_path / "run.units.json"
    assert path.read_text().splitlines()[0] == ",".join(columns)  # names unchanged
    assert read_units(path) == {
        "time": "s",
        "i_a": "A",
        "omega_m": "rad/s",
        "theta_m": "rad",
        "plant.theta[1]": "rad",
        "observer.tau_reac_hat": "N.m",
        "observer.mode": "1",
    }


def test_tool_names_in_the_csv_and_its_units_and_read_back(tmp_path: Path) -> None:
    path = tmp_path / "run.csv"
    write_csv(path, {**LOG, "observer.theta_hat[1]": T}, units={"observer.theta_hat[1]": "rad"},
              tool_names=True)  # fmt: skip
    header = path.read_text().splitlines()[0]
    assert header == "time,i_a,omega_m,theta_m,observer_theta_hat_1"
    assert json.loads(units_path(path).read_text())["observer_theta_hat_1"] == "rad"
    log = read_log(path)
    assert isinstance(log, DriveLog) and np.allclose(log.columns["theta_m"], T**2)


def test_a_file_without_units_reads_as_before(tmp_path: Path) -> None:
    path = tmp_path / "old.csv"
    path.write_text("time,i_a,omega_m,theta_m\n0,0,0,0\n0.001,0.5,0.1,0.0001\n")
    assert len(read_log(path)) == 2 and read_units(path) == {}


def test_a_chain_report_with_tool_names_is_still_a_chain(tmp_path: Path) -> None:
    path = tmp_path / "chain.json"
    report = {"J[1]": 1e-4, "k[1]": 50.0, "B[1]": 1e-3, "masses": 1, "std": {"J[1]": 1e-6}}
    path.write_text(json.dumps(tool_keys(report)))
    assert read_chain(path) == Chain(J=(1e-4,), k=(50.0,), B=(1e-3,), J_std=(1e-6,))


def test_excite_writes_units_and_tool_names(tmp_path: Path, capsys) -> None:
    out = tmp_path / "excitation.csv"
    args = ["excite", "--band", "3", "150", "--current-limit", "1", "--out", str(out)]
    assert main([*args, "--tool-names"]) == 0
    assert out.read_text().splitlines()[0] == "time,i_ref"
    assert read_units(out) == {"time": "s", "i_ref": "A"}


def test_identify_out_has_the_observer_units(fmus: Path, tmp_path: Path, capsys) -> None:
    log, out = tmp_path / "log.csv", tmp_path / "estimates.csv"
    t = np.arange(200) * 1e-3
    write_csv(log, {"time": t, "i_a": np.full(200, 0.2), "omega_m": 10 * t, "theta_m": 5 * t**2})
    command = ["identify", str(log), "--fmus", str(fmus), "--out", str(out), "--tool-names"]
    assert main([*command, "--set", "mode=2", "--json"]) == 0
    final = json.loads(capsys.readouterr().out)
    assert "theta_hat_1" in final and "theta_hat[1]" not in final
    units = read_units(out)
    header = out.read_text().splitlines()[0].split(",")
    assert list(units) == header and "theta_hat_1" in header
    assert units["time"] == "s" and units["tau_reac_hat"] == "N.m"
    assert units["theta_hat_1"] == "rad" and units["id_valid"] == "1"
    assert all(units.values()), {k: v for k, v in units.items() if not v}


@pytest.mark.parametrize("bad", ["a[1]", "a.1"])
def test_two_columns_that_become_one_name_are_refused(tmp_path: Path, bad: str) -> None:
    from arcosim.errors import UserError

    with pytest.raises(UserError, match="--tool-names"):
        write_csv(tmp_path / "x.csv", {"a_1": T, bad: T}, tool_names=True)
