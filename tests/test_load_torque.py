"""The load torque estimate end to end: plant FMU with tau_ext, observer FMU with
load_mass, the offline tool (``arcosim identify --method load-torque``) and scoring."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from arcosim.experiments.load_scores import score, step_truth
from arcosim.experiments.scenarios import LoadProfile, recording_columns, run_scenario
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.load_observer import LoadTorqueObserver
from arcosim.fmu.flexchain.model_observer import NoiseModel
from arcosim.host.instance import FmuInstance
from arcosim.host.master import cosimulate
from arcosim.logs import write_csv
from tests.test_load_observer import predicted_error

H = 1e-3
IDEAL = {"encoder_cpr": 0, "i_noise_std": 0.0, "f_c": 0.0}
D = 2.6e-3  # N·m, on mass 3


def test_ideal_sensors_follow_the_filters_own_prediction(build_fmus) -> None:
    """Ideal sensors, the true chain, no Coulomb friction: the DOB gives G[τ̄_1] exactly
    (docs/method.md), so the only model error left is the motor angle taken linear
    between samples, off by at most |θ̈_m| h²/8 in angle and |θ̈_m| h/2 in speed: a
    torque error of at most k_1 |θ̈_m| h²/8 + B_1 |θ̈_m| h/2 in τ̂_reac, which reaches the
    estimate with a gain of at most 1 (the filter's DC gain; it only falls with
    frequency). So the FMU's tau_load_hat must equal D minus the filter's own predicted
    error after a step, to within that bound, at every sample."""
    folder = build_fmus(3)
    t = np.arange(8000) * H
    current = 0.6 * np.sin(3.0 * t) + 0.1 * np.sin(45.0 * t)
    start = 500
    tau = np.where(np.arange(len(t)) >= start, D, 0.0)  # held over the step from t_k
    with (
        FmuInstance(folder / "MotorChainPlant.fmu", "plant") as p,
        FmuInstance(folder / "ReactionTorqueObserver.fmu", "observer") as o,
    ):
        run = cosimulate(
            p,
            o,
            current,
            H,
            ["omega_m_true"],
            ["tau_load_hat"],
            IDEAL,
            {"encoder_cpr": 0, "D_m": defaults.D_M, "estimator": 1, "load_mass": 3},
            plant_inputs={"tau_ext[3]": tau},
        )
        assert not o.messages, o.messages
    estimate = run["observer.tau_load_hat"]
    alpha = np.max(np.abs(np.diff(run["plant.omega_m_true"]))) / H
    bound = defaults.K * alpha * H**2 / 8 + defaults.B * alpha * H / 2
    obs = LoadTorqueObserver(
        defaults.J, (defaults.K,) * 3, (defaults.B,) * 3, 100.0, _noise(), 0.0, 3
    )
    model = obs.model(H)
    e = predicted_error(model, len(t) - start)
    expected = np.zeros(len(t) + 1)
    z = np.zeros(2)
    Phi, phi = np.array(model.Phi), np.array(model.phi)
    for j, err in enumerate(e):  # the torque over the step ending at sample start + 1 + j
        z = Phi @ z + phi * D * (1.0 - err)
        expected[start + 1 + j] = z[0]
    print(f"max deviation {np.max(np.abs(estimate - expected)):.3g} N.m, bound {bound:.3g} N.m")
    assert np.max(np.abs(estimate - expected)) <= bound
    assert abs(estimate[-1] - D) <= 1e-3 * D + bound  # and it got there
    assert bound < 0.01 * D  # the check is tight


def _noise() -> NoiseModel:
    """The observer FMU's default noise model with an exact angle (encoder_cpr = 0)."""
    return NoiseModel(0.0, 1e-4, 1.5e-3)


@pytest.mark.system
@pytest.mark.slow
def test_offline_tool_gives_the_fmus_estimate(build_fmus, tmp_path: Path) -> None:
    """``arcosim identify LOG --method load-torque`` runs the FMU's code: same numbers."""
    profile = LoadProfile(duration=4.0, sine_time=2.5)
    observer = {"D_m": defaults.D_M, "f_c": defaults.F_C}
    recording = run_scenario(profile.scenario(), 3, observer=observer, fmu_dir=build_fmus(3))
    log = write_csv(tmp_path / "log.csv", recording_columns(recording))
    (tmp_path / "dist").symlink_to(build_fmus(3), target_is_directory=True)
    chain = {"masses": 3, **{f"J[{i + 1}]": x for i, x in enumerate(defaults.J)}}
    chain.update(
        {f"{p}[{i}]": v for i in (1, 2, 3) for p, v in (("k", defaults.K), ("B", defaults.B))}
    )
    (tmp_path / "bare.json").write_text(json.dumps(chain))
    (tmp_path / "chain.json").write_text(json.dumps({**chain, **observer}))  # as fitted
    command = [sys.executable, "-m", "arcosim", "identify", str(log), "--method", "load-torque"]
    command += ["--chain", "chain.json", "--set", "load_mass=3", "--out", "est.csv", "--json"]
    result = subprocess.run(command, capture_output=True, text=True, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["load_mass"] == 3 and report["samples"] == len(recording.time)
    assert "D_m" not in report.get("assumptions", {}).get("defaults", "")
    offline = np.genfromtxt(tmp_path / "est.csv", delimiter=",", names=True)["tau_load_hat"]
    fmu = recording["observer.tau_load_hat"]
    assert np.max(np.abs(offline - fmu)) <= 1e-9 * np.max(np.abs(fmu))
    assert report["final"] == pytest.approx(fmu[-1], rel=1e-9)
    missing = subprocess.run(command[:7], capture_output=True, text=True, cwd=tmp_path)
    assert missing.returncode == 2 and "--set load_mass=I" in missing.stderr
    bare = [*command[:8], "bare.json", "--set", "load_mass=3"]
    text = subprocess.run(bare, capture_output=True, text=True, cwd=tmp_path)
    assert text.returncode == 0, text.stderr
    assert "assumption, defaults: not given" in text.stdout and "D_m = 0" in text.stdout


def test_score_of_a_known_estimate() -> None:
    """The scores of an estimate built to have a known lag, offset and settling."""
    t = np.arange(15001) * H
    profile = LoadProfile()
    size = profile.size()
    truth = step_truth(t, profile.torque(t))
    lag = 0.3
    estimate = np.where(t >= 1.5, size * 1.02, 0.0)
    sine = t >= profile.sine_time
    estimate[sine] = size * 0.9 * np.cos(2.0 * (t[sine] - profile.sine_time - lag))
    s = score(t, estimate, truth, 1.0, 7.0, 2.0, 4.0, 15.0 - 2 * math.pi)  # two periods
    assert s.size == pytest.approx(size)
    assert s.settling_s == pytest.approx(0.5, abs=2 * H)
    assert s.settled_mean_percent == pytest.approx(2.0, abs=1e-6)
    assert s.settled_max_percent == pytest.approx(2.0, abs=1e-6)
    assert s.sine_amplitude_ratio == pytest.approx(0.9, rel=1e-6)
    lag -= H  # the truth is the torque over the step ending at each sample
    assert s.sine_lag_s == pytest.approx(lag, abs=1e-6)
    expected_rms = math.sqrt(0.5 * (1 + 0.81 - 2 * 0.9 * math.cos(2.0 * lag))) * 100
    assert s.sine_rms_percent == pytest.approx(expected_rms, rel=1e-3)
