"""The public-record benchmark's readers, its two-encoder reference and its skip path.

No record is in the repository and no test touches the network: the readers parse tiny
files written here in each record's documented format, and the skip path is checked on
an empty folder.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from scipy.io import savemat

from arcosim.cli import main
from arcosim.errors import UserError
from benchmarks import public_loaders as loaders
from benchmarks import public_records


def test_emps_reader_maps_the_linear_axis(tmp_path):
    n, h = 50, 1e-3
    t = (np.arange(n) * h + 1e-8 * np.sin(np.arange(n)))[:, None]  # a logger's jittery time
    qm = (np.round(np.sin(np.arange(n) / 7.0) * 1e4) * loaders.EMPS_COUNT)[:, None]
    vir = np.linspace(-1.0, 1.0, n)[:, None]
    path = tmp_path / "DATA_EMPS.mat"
    savemat(path, {"t": t, "qm": qm, "qg": qm, "vir": vir, "gtau": 35.15, "kp": 160.18, "kv": 2.0})
    c = loaders.load_emps(path)
    assert np.allclose(np.diff(c.columns["time"]), h, rtol=0, atol=1e-15)  # constant step
    assert np.array_equal(c.columns["i_a"], vir.ravel())
    assert np.allclose(c.columns["omega_m"][1:], np.diff(qm.ravel()) / h)
    assert c.units["theta_m"] == "m" and c.units["i_a"] == "V"
    values = public_records.settings_of(c.settings)
    assert values["k_to"] == 35.15
    assert 2 * np.pi / values["encoder_cpr"] == pytest.approx(5e-8, rel=1e-8)  # 50 nm a count


def test_hsm150_reader_takes_the_measured_current_or_the_command(tmp_path):
    n = 40
    data = np.column_stack(
        [
            np.arange(n) * 1e-3,  # time, s
            np.zeros(n),  # position reference
            np.cumsum(np.full(n, 2 * np.pi / 10000)),  # position, rad
            np.full(n, 0.62832),  # velocity, rad/s
            np.full(n, 0.05),  # input torque, N·m
            np.full(n, 0.0458),  # torque measurement, N·m
            np.full(n, 1.0),  # motor current, A
        ]
    )
    path = tmp_path / "idf_pos_0.065_2.mat"
    savemat(path, {"data": data, "Cu": 0.0458, "J": 1.2e-4, "B": 7.03e-5})
    measured = loaders.load_hsm150(path)
    command = loaders.load_hsm150(path, "command")
    assert np.array_equal(measured.columns["i_a"], data[:, 6])
    assert np.allclose(command.columns["i_a"], 0.05 / 0.0458)
    assert np.array_equal(measured.columns["theta_m"], data[:, 2])
    assert public_records.settings_of(measured.settings) == {
        "k_to": 0.0458,
        "J_mo": 1.2e-4,
        "encoder_cpr": 10000.0,
    }
    with pytest.raises(UserError, match="measured"):
        loaders.load_hsm150(path, "voltage")


def test_motor_bench_reader_and_a_missing_variable(tmp_path):
    n = 30
    theta = np.linspace(0.0, 1e-3, n)[:, None]
    path = tmp_path / "MultisineTypeA.mat"
    fields = {"time": np.arange(n)[:, None] * 400.0, "iq_adx": np.ones((n, 1))}
    fields |= {"theta_mx": theta, "theta_my": 2 * theta, "fs": 2500, "nrofs": 10}
    savemat(path, fields | {"fl": 11, "fh": 250})
    c = loaders.load_motor_bench(path)
    assert c.columns["time"][-1] == pytest.approx((n - 1) * 4e-4)
    assert np.allclose(c.columns["theta_load"], -2 * theta.ravel())  # the examples' sign
    assert c.extra == {"period": 10.0, "f_low": 11.0, "f_high": 250.0}
    savemat(path, fields)  # no fl, fh
    with pytest.raises(UserError, match="no variable fl, fh"):
        loaders.load_motor_bench(path)


def test_two_encoder_reference_recovers_a_two_mass_chain():
    # The periodic steady state of a known two-mass chain under a multi-sine, made exactly
    # in the frequency domain; the fit must give the chain back.
    fs, period, periods = 2500.0, 2500, 3
    J_m, J_L, k, c, delay = 4.8e-3, 4.9e-3, 560.0, 0.046, 1.2e-4
    f = np.fft.rfftfreq(period, 1 / fs)
    lines = (f >= 11) & (f <= 250)
    rng = np.random.default_rng(1)
    current = np.zeros(f.size, complex)
    current[lines] = np.exp(2j * np.pi * rng.random(lines.sum())) * period
    motor, load = np.zeros(f.size, complex), np.zeros(f.size, complex)
    motor[lines], load[lines] = (
        current[lines] * r
        for r in loaders.two_mass_frf(2 * np.pi * f[lines], J_m, J_L, k, c, delay)
    )
    i_a, theta_m, theta_l = (
        np.tile(np.fft.irfft(x, period), periods) for x in (current, motor, load)
    )
    columns = {"time": np.arange(periods * period) / fs, "i_a": i_a}
    columns |= {"theta_m": theta_m, "theta_load": theta_l}
    extra = {"period": float(period), "f_low": 11.0, "f_high": 250.0}
    ref = loaders.two_mass_reference(loaders.Converted(columns, {}, (), "", extra))
    for name, true in (("J_m", J_m), ("J[1]", J_L), ("k[1]", k), ("B[1]", c)):
        assert ref[name] == pytest.approx(true, rel=1e-6), name
    assert ref["clamped_mode"] == pytest.approx(np.sqrt(k / J_L), rel=1e-6)
    assert ref["rms_relative_error"] < 1e-8


def test_missing_files_are_skipped_naming_where_to_get_them(tmp_path, capsys):
    cwd = os.getcwd()
    os.chdir(os.path.dirname(os.path.dirname(__file__)))  # `arcosim bench` finds the checkout
    try:
        assert main(["bench", "public", "--data", str(tmp_path), "--work", str(tmp_path)]) == 0
    finally:
        os.chdir(cwd)
    out = capsys.readouterr().out
    for record in public_records.RECORDS:
        line = next(x for x in out.splitlines() if x.startswith(f"skip {record.name}:"))
        assert str(tmp_path / record.file) in line
        assert f"get {record.file} from https://" in line
    assert "https://github.com/malik-robert/HSM150-data/raw/main/" in out


def test_refusal_and_comparison():
    err = "arcosim identify: fitting…\narcosim: error: --masses 0: must be 1 to 20\n"
    assert public_records.refusal(err) == "--masses 0: must be 1 to 20"
    assert public_records.refusal("") == ""
    result = {
        "reference": None,
        "published": {"J_total": 100.0},
        "runs": [
            {"label": "mode 0", "quantities": {"J_total": 101.0, "f_c": 2.0}, "refusal": ""},
            {"label": "n = 0", "quantities": {"J_total (bound)": 99.0}, "refusal": ""},
            {"label": "n = 0", "quantities": {}, "refusal": "--masses 0: must be 1 to 20"},
        ],
    }
    rows = public_records.comparison("emps", result)
    assert rows[0] == ["emps", "mode 0", "J_total", "100", "101", "+1.0 %"]
    assert rows[1][2:] == ["f_c", "", "2", ""]
    assert rows[2][2:] == ["J_total (bound)", "100", "≤ 99", "excludes it"]
    assert rows[3][2:5] == ["refused", "", "--masses 0: must be 1 to 20"]
