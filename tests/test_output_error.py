"""Output-error identification (cosim/identification/fit/output_error.py, uniform_fit.py), its
CLI, and
the accuracy benchmark in quick mode."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import signal

from arcosim.cli import main
from arcosim.experiments.scenarios import SCENARIOS, run_scenario
from arcosim.fmu.flexchain import defaults
from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.output_error import predict
from arcosim.identification.fit.uniform_fit import uniform_chain
from arcosim.identification.records.record import MotorRecord, constant_step, motor_record
from benchmarks.accuracy import ACTUATOR

H = 1e-3


def synthetic(seconds: float, noise: float, seed: int = 0) -> MotorRecord:
    """The bench driven by a broadband motor angle; τ̂ = the model's, plus white noise
    through G (the shape of the DOB's current noise)."""
    t = np.arange(round(seconds / H) + 1) * H
    rng = np.random.default_rng(seed)
    theta = sum(
        0.05 / w * np.sin(w * t + rng.uniform(0, 2 * np.pi)) for w in (3, 7, 13, 17, 22, 30, 60)
    )
    clean = MotorRecord(H, theta, np.zeros_like(t), 100.0)
    tau = predict(clean, defaults.J, [defaults.K] * 3, [defaults.B] * 3)
    a = math.exp(-100.0 * H)
    tau = tau + signal.lfilter([1 - a], [1, -a], noise * rng.standard_normal(len(t)))
    return MotorRecord(H, theta, tau, 100.0)


def test_fit_recovers_k_and_b_with_an_honest_standard_error() -> None:
    fit = uniform_chain(synthetic(10.0, 2e-4), defaults.J)
    k, B = fit.values
    assert k == pytest.approx(defaults.K, rel=1e-3)
    assert abs(B - defaults.B) <= 3 * fit.std[1]
    assert fit.std[0] > 0 and fit.std[1] > 0
    assert "scan of the cost" in fit.start_note


def test_noise_free_fit_is_exact() -> None:
    fit = uniform_chain(synthetic(5.0, 0.0), defaults.J)
    assert fit.values[0] == pytest.approx(defaults.K, rel=1e-6)
    assert fit.values[1] == pytest.approx(defaults.B, rel=1e-4)


def test_a_record_without_torque_is_refused() -> None:
    """A log whose reaction torque never moved cannot show a resonance."""
    t = np.arange(5001) * H
    record = MotorRecord(H, 0.5 * np.sin(t), np.zeros_like(t), 100.0)
    with pytest.raises(IdentificationError, match="shows no resonance"):
        uniform_chain(record, defaults.J)


def test_a_variable_step_is_refused() -> None:
    with pytest.raises(IdentificationError, match="constant sample step"):
        constant_step(np.array([0.0, 1e-3, 2e-3, 4e-3]))


def test_prediction_matches_the_observer_on_an_ideal_co_simulation(build_fmus) -> None:
    """The chain model, driven by the plant's motor angle, predicts the DOB's τ̂_reac:
    what is left is the DOB's own error (docs/method.md: 0.07 %) and friction at reversals."""
    recording = run_scenario(
        SCENARIOS["flexible"],
        plant={"seed": 1},
        ideal=True,
        record_plant=["i_a", "omega_m", "theta_m"],
        record_observer=["tau_reac_hat"],
        fmu_dir=build_fmus(3),
    )
    s = recording.signals
    record = motor_record(
        recording.time, s["plant.i_a"], s["plant.omega_m"], s["plant.theta_m"], ACTUATOR, 100.0
    )
    assert record.velocity_source == "measured"
    model = predict(record, defaults.J, [defaults.K] * 3, [defaults.B] * 3)
    error = np.sqrt(np.mean((model - record.tau_hat) ** 2))
    assert error < 0.03 * np.sqrt(np.mean(record.tau_hat**2))  # measured 1.9 %


@pytest.mark.slow
def test_identify_output_error_cli(build_fmus, tmp_path, capsys) -> None:
    log = tmp_path / "flex.csv"
    assert main(["simulate", "--scenario", "flexible", "--out", str(log)]) == 0
    capsys.readouterr()
    args = ["identify", str(log), "--method", "output-error", "--json"]
    assert main([*args, "--set", "D_m=2e-5", "--set", "f_c=2e-3"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert set(report["std"]) == {"k_hat", "B_hat"}
    assert report["k_hat"] == pytest.approx(defaults.K, rel=0.005)
    assert "backward difference" in report["velocity"]
    assert main([*args, "--set", "J[7]=1"]) == 2
    assert "has no variable 'J[7]'" in capsys.readouterr().err


@pytest.mark.slow
def test_accuracy_benchmark_runs_in_quick_mode(build_fmus, tmp_path) -> None:
    """CI proves the benchmark still runs (the bench, one seed); no thresholds here."""
    code = main(
        ["bench", "accuracy", "--quick", "--seeds", "1", "--b-seeds", "0", "--out", str(tmp_path)]
    )
    assert code == 0
    table = (tmp_path / "accuracy.md").read_text()
    for method in (
        "eq. 21 (literal)",
        "eq. 21 + kappa",
        "output error",
        "recursion",
        "model-based",
        "naive theta_i = theta_m",
    ):
        assert f"| {method} | bench (n=3) |" in table
    summary = json.loads((tmp_path / "accuracy.json").read_text())
    naive = summary["results"]["bench (n=3)"]["state"]["naive theta_i = theta_m"][0]
    assert all(0.9 < x < 1.1 for x in naive)  # the naive estimate scores 1 by definition
