"""Whole-chain identification (cosim/identification/fit/whole_chain.py, modes/detection.py,
chain_modes.py, encoder_fit.py, kalman.py): every J_i, k_i, B_i from the motor side alone."""

from __future__ import annotations

import json
import shlex

import numpy as np
import pytest

from arcosim.cli import main
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit import encoder_fit, kalman
from arcosim.identification.fit.output_error import ParameterFit, predict
from arcosim.identification.fit.whole_chain import fit_chain, identify_whole_chain, names, split
from arcosim.identification.modes.chain_modes import chain_from_modes, driving_point_modes
from arcosim.identification.records.record import EncoderRecord, MotorRecord, encoder_record

H = 1e-3
J = (4e-4, 8e-4)
K = (0.3, 0.2)
B = (2e-5, 1.5e-5)
#: The identification excitation's lines (rad/s): 40, log-spaced over 3 … 150.
LINES = np.geomspace(3.0, 150.0, 40)


def record(seconds: float, lines: np.ndarray = LINES) -> MotorRecord:
    """A two-mass chain with unequal springs, driven by a broadband motor angle;
    τ̂ = the model's (noise-free)."""
    t = np.arange(round(seconds / H) + 1) * H
    rng = np.random.default_rng(3)
    theta = sum(0.02 / w * np.sin(w * t + rng.uniform(0, 2 * np.pi)) for w in lines)
    clean = MotorRecord(H, theta, np.zeros_like(t), 100.0)
    return MotorRecord(H, theta, predict(clean, J, K, B), 100.0)


def test_a_chain_is_rebuilt_from_its_clamped_modes_and_residues() -> None:
    """Five unequal masses and springs → (p_i, r_i) → the same chain (Lanczos)."""
    inertias = (2e-4, 3e-4, 2.5e-4, 3e-4, 2e-4)
    springs = (0.4, 0.3, 0.5, 0.35, 0.45)
    p, r = driving_point_modes(inertias, springs)
    rebuilt_J, rebuilt_k = chain_from_modes(p, r)
    np.testing.assert_allclose(rebuilt_J, inertias, rtol=1e-9)
    np.testing.assert_allclose(rebuilt_k, springs, rtol=1e-9)
    # the static torque of a free chain is zero: k_1 = Σ r_i / p_i²
    assert np.sum(r / p**2) == pytest.approx(springs[0], rel=1e-12)


@pytest.mark.parametrize(
    "p, r", [((10.0, 10.0), (1.0, 1.0)), ((10.0, 20.0), (1.0, 0.0)), ((-1.0,), (1.0,))]
)
def test_modes_no_chain_has_are_refused(p: tuple, r: tuple) -> None:
    with pytest.raises(ValueError):
        chain_from_modes(p, r)


@pytest.mark.slow
def test_every_inertia_stiffness_and_damping_of_an_unequal_chain_is_recovered() -> None:
    """Noise-free: nothing but the motor angle and the reaction torque is given."""
    result = fit_chain(record(10.0), 2)
    assert result.names == names(2) == ["J[1]", "J[2]", "k[1]", "k[2]", "B[1]", "B[2]"]
    fitted_J, fitted_k, fitted_B = split(result.values, 2)
    np.testing.assert_allclose(fitted_J, J, rtol=1e-4)
    np.testing.assert_allclose(fitted_k, K, rtol=1e-4)
    np.testing.assert_allclose(fitted_B, B, rtol=1e-2)
    # the start already holds the modes: the chain's clamped frequencies within 1 %
    np.testing.assert_allclose(result.extra["modes_rad_s"], driving_point_modes(J, K)[0], rtol=1e-2)
    assert "subspace" in result.start_note


def test_auto_reads_the_number_of_masses_from_the_record() -> None:
    """The stabilization diagram shows two modes, both far above their standard errors."""
    choice = identify_whole_chain(record(10.0), "auto")
    assert choice.n == 2 and choice.seen == 2
    assert min(choice.fit.extra["residue_t_values"]) > 30
    np.testing.assert_allclose(
        choice.fit.extra["modes_rad_s"], driving_point_modes(J, K)[0], rtol=1e-3
    )


@pytest.mark.slow
def test_a_record_that_cannot_determine_the_chain_is_refused_with_what_to_do() -> None:
    """τ̂ unrelated to the motor's motion. (A single sine is not such a record: its
    start rings the modes, and with ζ ≈ 1e-3 the ringing determines the chain.)"""
    good = record(10.0)
    noise = np.random.default_rng(1).normal(0.0, 1e-3, len(good.theta_m))
    with pytest.raises(IdentificationError, match=r"lightly damped mode|carry no reaction torque"):
        fit_chain(MotorRecord(H, good.theta_m, noise, 100.0), 2)


def test_a_record_too_short_for_its_modes_is_refused() -> None:
    with pytest.raises(
        IdentificationError, match=r"too short to find 5 modes.*record at least 1\.1 s"
    ):
        fit_chain(record(1.0), 5)


@pytest.mark.parametrize("masses", ["two", "-1", "2.5"])
def test_a_bad_number_of_masses_is_refused(masses: str) -> None:
    with pytest.raises(IdentificationError, match="masses"):
        identify_whole_chain(record(3.0), masses)


def test_a_chain_without_masses_is_refused() -> None:
    with pytest.raises(IdentificationError, match="at least one load mass"):
        fit_chain(record(3.0), 0)


@pytest.mark.slow
def test_identify_whole_chain_cli_finds_the_bench_from_the_motor_alone(
    build_fmus, tmp_path, capsys
) -> None:
    """The identification scenario, realistic sensors; only the actuator is given."""
    log = tmp_path / "identification.csv"
    assert main(["simulate", "--scenario", "identification", "--out", str(log)]) == 0
    capsys.readouterr()
    args = ["identify", str(log), "--method", "whole-chain", "--masses", "auto", "--json"]
    assert main([*args, "--set", "D_m=2e-5", "--set", "f_c=2e-3"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["masses"] == report["masses_seen"] == 3
    for i in range(3):
        assert report[f"J[{i + 1}]"] == pytest.approx(defaults.J[i], rel=0.02)
        assert report[f"k[{i + 1}]"] == pytest.approx(defaults.K, rel=0.02)
        assert report["std"][f"B[{i + 1}]"] > 0
    assert min(report["residue_t_values"]) > 30
    assert report["assumptions"]["friction"].startswith("given")
    assert (report["D_m"], report["f_c"]) == (2e-5, 2e-3)  # the chain file carries them


@pytest.mark.slow
def test_the_printed_set_line_estimates_every_load_angle(build_fmus, tmp_path, capsys) -> None:
    """The whole-chain text output ends with the observer's --set line; pasted back, it
    runs the model-based observer (estimator 1, the fitted friction), which follows every
    load angle: within 5 % of its swing about the motor (the recursion, estimator 0, the
    FMU's default, scores 0.45 on mass 1 and diverges from mass 2 on)."""
    log = tmp_path / "identification.csv"
    assert main(["simulate", "--scenario", "identification", "--out", str(log)]) == 0
    capsys.readouterr()
    assert main(["identify", str(log), "--method", "whole-chain", "--masses", "auto"]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    line = shlex.split(last.split(":", 1)[1])
    assert {"estimator=1", "--masses"} <= set(line), last
    assert any(a.startswith("D_m=") for a in line) and any(a.startswith("f_c=") for a in line)
    states = tmp_path / "states.csv"
    assert main(["identify", str(log), *line, "--out", str(states)]) == 0
    data = np.genfromtxt(states, delimiter=",", names=True, deletechars="")
    truth = np.genfromtxt(log, delimiter=",", names=True, deletechars="")
    for i in (1, 2, 3):
        swing = truth[f"plant.theta[{i}]"] - truth["plant.theta_m_true"]
        error = data[f"theta_hat[{i}]"] - truth[f"plant.theta[{i}]"]
        assert np.sqrt(np.mean(error**2) / np.mean(swing**2)) < 0.05, i


def test_whole_chain_reads_n_from_the_record_unless_given(tmp_path, capsys) -> None:
    """Without --masses the whole-chain fit searches n as `check` assumes; given, it fits n."""
    log = tmp_path / "log.csv"
    log.write_text("time,i_a,omega_m,theta_m\n0,0,0,0\n0.001,0,0,0\n0.002,0,0,0\n")
    assert main(["identify", str(log), "--method", "whole-chain"]) == 1
    assert "n = 0 … " in capsys.readouterr().err
    assert main(["identify", str(log), "--method", "whole-chain", "--masses", "2"]) == 1
    assert "n = 2 (" in capsys.readouterr().err


def test_masses_auto_needs_the_whole_chain_method(build_fmus, tmp_path, capsys) -> None:
    log = tmp_path / "log.csv"
    log.write_text("time,i_a,omega_m,theta_m\n0,0,0,0\n0.001,0,0,0\n0.002,0,0,0\n")
    assert main(["identify", str(log), "--masses", "auto"]) == 2
    assert "'auto' needs --method whole-chain" in capsys.readouterr().err


def test_the_prediction_error_fit_takes_the_encoder_counts_for_what_they_are() -> None:
    """Motor + two-mass chain driven by a multi-sine torque, read by a 2000-count
    encoder; from a start 1 % off (B 30 % off), every parameter comes back within
    its standard error's reach."""
    actuator = Actuator(defaults.J_M, defaults.K_T, 0.0, 0.0, defaults.D_M, 0.0)
    t = np.arange(10001) * H
    rng = np.random.default_rng(5)
    current = sum(0.1 * np.sin(w * t + rng.uniform(0, 2 * np.pi)) for w in LINES)
    count = 2 * np.pi / 2000
    zeros = np.zeros_like(t)
    exact = EncoderRecord(
        H, defaults.K_T * current, zeros, zeros, count, defaults.J_M, defaults.D_M, 0.0, 1e-4
    )
    truth_drive = kalman.Drive(np.array(J), np.array(K), np.array(B), defaults.D_M, 0.0)
    A, Bd = kalman.discrete_drive(exact, truth_drive)
    x = np.zeros(len(A))
    theta, velocity = np.empty_like(t), np.empty_like(t)
    for step, torque in enumerate(exact.torque):
        if step:
            x = A @ x + Bd[:, 0] * torque
        theta[step], velocity[step] = x[0], x[3]
    counts = np.floor(theta / count) * count
    record = encoder_record(t, current, counts, actuator, 2000)
    start_values = np.array([*J, *K, *B]) * np.array([1.01, 0.99, 1.01, 0.99, 1.3, 0.7])
    start = ParameterFit(names(2), start_values, start_values * 0, start_values, "test", 0, 0, 1, 0)
    motor = MotorRecord(H, counts, np.zeros_like(t), 100.0)
    refined = encoder_fit.refine(record, motor, start, 2)
    truth = np.array([*J, *K, *B])
    np.testing.assert_allclose(refined.values[:4], truth[:4], rtol=2e-3)
    assert np.all(np.abs(refined.values - truth) <= 3 * refined.std)
    assert refined.extra["start_fit"]["B[1]"] == start_values[4]
    assert 0.8 < refined.extra["innovation_variance"] < 1.2  # the counts' q²/12, as assumed
    # the smoother's motor velocity (the friction's sign) beats the smoothed derivative
    smoothed = kalman.Kalman.of(record, truth_drive).smoothed(record, truth_drive)
    assert smoothed.shape == (len(t), 6)
    derivative_error = np.sqrt(np.mean((record.velocity - velocity) ** 2))
    smoother_error = np.sqrt(np.mean((smoothed[:, 3] - velocity) ** 2))
    assert smoother_error < 0.5 * derivative_error
    np.testing.assert_allclose(smoothed[:, 0], theta, atol=count / 2)  # finer than a count


def test_an_encoder_without_counts_is_refused() -> None:
    actuator = Actuator(defaults.J_M, defaults.K_T)
    with pytest.raises(IdentificationError, match="counts per revolution"):
        encoder_record(np.arange(5) * H, np.zeros(5), np.zeros(5), actuator, 0)
