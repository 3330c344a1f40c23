"""Co-simulation master, excitation signals, and the simulate / identify commands."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from arcosim.experiments import current_commands
from arcosim.experiments.scenarios import SCENARIOS, run_scenario
from arcosim.host.instance import FmuInstance
from arcosim.host.master import cosimulate

IDEAL = {"encoder_cpr": 0, "i_noise_std": 0.0}


def arcosim(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "arcosim", *args], capture_output=True, text=True, cwd=cwd
    )


@pytest.fixture(scope="module")
def workdir(build_fmus, tmp_path_factory) -> Path:
    """A working folder, with the FMUs for n = 3 built into the session cache."""
    build_fmus(3)
    return tmp_path_factory.mktemp("work")


def spectrum(x: np.ndarray, h: float, window: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies (rad/s) and energy of ``x`` (Hann-windowed against leakage if asked)."""
    power = np.abs(np.fft.rfft(x * np.hanning(len(x)) if window else x)) ** 2
    return 2 * np.pi * np.fft.rfftfreq(len(x), h), power


# -- master ------------------------------------------------------------------------


def test_master_counts_steps_sets_parameters_and_records(build_fmus) -> None:
    folder = build_fmus(3)
    steps, h, t0 = 250, 2e-3, 1.5
    with (
        FmuInstance(folder / "MotorChainPlant.fmu", "p") as p,
        FmuInstance(folder / "ReactionTorqueObserver.fmu", "o") as o,
    ):
        r = cosimulate(
            p,
            o,
            [0.3] * steps,
            h,
            ["theta_m_true", "k[1]"],
            ["d_hat", "id_valid"],
            {**IDEAL, "k[1]": 0.25},
            {"g_dist": 250.0, "mode": 1},
            t0=t0,
        )
        assert p.time == pytest.approx(t0 + steps * h) and o.time == pytest.approx(t0 + steps * h)
    assert len(r.time) == steps + 1
    np.testing.assert_array_equal(r.time, t0 + np.arange(steps + 1) * h)  # t0 + k h, not summed
    assert np.all(r["plant.k[1]"] == 0.25)  # the parameter reached the plant
    assert r["plant.theta_m_true"][0] == 0.0 and r["plant.theta_m_true"][-1] > 0.0
    assert r["observer.d_hat"][0] == 0.0 and set(np.unique(r["observer.id_valid"])) <= {0.0, 1.0}


def test_master_refuses_bad_arguments(build_fmus) -> None:
    from arcosim.errors import UserError

    folder = build_fmus(3)
    with (
        FmuInstance(folder / "MotorChainPlant.fmu", "p") as p,
        FmuInstance(folder / "ReactionTorqueObserver.fmu", "o") as o,
    ):
        with pytest.raises(UserError, match="ordering 'sideways'"):
            cosimulate(p, o, [0.0], 1e-3, ordering="sideways")
        with pytest.raises(UserError, match=re.escape("step size 0.0")):
            cosimulate(p, o, [0.0], 0.0)


def test_a_refused_step_stops_the_run_with_the_fmu_log(build_fmus) -> None:
    from arcosim.errors import UserError

    folder = build_fmus(3)
    with (
        FmuInstance(folder / "MotorChainPlant.fmu", "p") as p,
        FmuInstance(folder / "ReactionTorqueObserver.fmu", "o") as o,
        pytest.raises(UserError, match=re.escape("J_m = -1.0 must be > 0")),
    ):
        cosimulate(p, o, [0.1] * 5, 1e-3, plant_parameters={"J_m": -1.0})


# -- excitations -------------------------------------------------------------------


def test_rigid_maneuver_stays_far_below_the_first_mode_and_returns_to_rest() -> None:
    h = 1e-3
    t = np.arange(round(SCENARIOS["rigid"].duration / h)) * h
    i = current_commands.rigid_maneuver(t)
    w, power = spectrum(i, h)
    assert power[w > 16.8 / 2].sum() < 1e-6 * power.sum()  # nothing near the first mode
    assert abs(i.sum() * h) < 1e-5 and abs(np.cumsum(i).sum() * h * h) < 1e-4  # ∫i = ∫∫i = 0
    assert np.max(np.abs(i)) == pytest.approx(3.0, rel=1e-3)


def test_rigid_maneuver_leaves_little_residual_vibration(build_fmus) -> None:
    """Twist left ringing 2 s after the maneuver: under 2 % of the twist it drove."""
    h = 1e-3
    t = np.arange(round(SCENARIOS["rigid"].duration / h)) * h
    current = np.r_[current_commands.rigid_maneuver(t), np.zeros(2000)]
    folder = build_fmus(3)
    with (
        FmuInstance(folder / "MotorChainPlant.fmu", "p") as p,
        FmuInstance(folder / "ReactionTorqueObserver.fmu", "o") as o,
    ):
        r = cosimulate(p, o, current, h, ["twist"], [], IDEAL)
    twist = r["plant.twist"]
    after = twist[len(t) :]
    assert np.sqrt(np.mean(after**2)) < 0.02 * np.max(np.abs(twist[: len(t)]))


def test_multisine_has_energy_only_at_its_frequencies() -> None:
    h, n = 1e-3, 2**14
    t = np.arange(n) * h
    lines = 2 * np.pi * np.array([5, 11, 40]) / (n * h)  # exact FFT bins
    w, power = spectrum(current_commands.multisine(t, 0.3, lines * 50, seed=2), h)
    bins = np.argsort(power)[-3:]
    np.testing.assert_allclose(np.sort(w[bins]), np.sort(lines * 50), rtol=1e-9)
    assert power[bins].sum() > 0.999999 * power.sum()
    peak = np.max(np.abs(current_commands.multisine(t, 0.3, lines, seed=2)))
    assert 0.1 < peak <= 0.3  # each line 0.3 / 3: the peak never exceeds the amplitude


def test_chirp_sweeps_its_band_only() -> None:
    h = 1e-3
    t = np.arange(10000) * h
    w, power = spectrum(current_commands.chirp(t, 0.2, 10.0, 100.0, 10.0), h)
    assert power[(w < 5) | (w > 130)].sum() < 0.01 * power.sum()


def test_filtered_random_is_below_its_cutoff() -> None:
    """4th-order Butterworth, causal: −24 dB per octave above the cut-off."""
    h = 1e-3
    t = np.arange(20000) * h
    x = current_commands.filtered_random(t, 0.15, 150.0, seed=3)
    w, power = spectrum(x, h, window=True)
    assert power[w > 450].sum() < 1e-3 * power.sum()
    # the rms of one 20 s realization: within 10 % of the set value
    assert np.sqrt(np.mean(x**2)) == pytest.approx(0.15, rel=0.1)
    np.testing.assert_array_equal(x, current_commands.filtered_random(t, 0.15, 150.0, seed=3))


# -- simulate and identify ---------------------------------------------------------


@pytest.mark.system
@pytest.mark.slow
def test_identify_on_a_simulated_log_gives_the_cosimulation_estimates(workdir) -> None:
    settings = ["--set", "observer.D_m=2e-5", "--set", "observer.f_c=2e-3"]
    sim = arcosim(
        "simulate",
        "--scenario",
        "rigid",
        "--duration",
        "12",
        *settings,
        "--out",
        "rigid.csv",
        "--json",
        cwd=workdir,
    )
    assert sim.returncode == 0, sim.stderr
    cosim_final = json.loads(sim.stdout)
    ident = arcosim(
        "identify",
        "rigid.csv",
        "--mode",
        "1",
        "--set",
        "D_m=2e-5",
        "--set",
        "f_c=2e-3",
        "--json",
        "--out",
        "estimates.csv",
        cwd=workdir,
    )
    assert ident.returncode == 0, ident.stderr
    final = json.loads(ident.stdout)
    # the replay's steps are t_k − t_{k−1} from the log, equal to h up to rounding
    assert final["k_hat"] == pytest.approx(cosim_final["k_hat"], rel=1e-9)
    assert final["k_hat"] != 0.0
    assert final["tau_reac_hat"] == pytest.approx(cosim_final["tau_reac_hat"], rel=1e-9)
    assert final["id_valid"] is True and final["self_id_rank_deficient"] is False
    written = np.genfromtxt(workdir / "estimates.csv", delimiter=",", names=True)
    assert written["k_hat"][-1] == final["k_hat"] and len(written) == 12001


@pytest.mark.system
@pytest.mark.slow
def test_identify_scale_converts_units(workdir) -> None:
    sim = arcosim(
        "simulate", "--scenario", "flexible", "--duration", "1", "--out", "si.csv", cwd=workdir
    )
    assert sim.returncode == 0, sim.stderr
    data = np.genfromtxt(workdir / "si.csv", delimiter=",", names=True)
    with open(workdir / "ma.csv", "w") as f:
        f.write("time,i_a,omega_m,theta_m\n")
        for row in data:
            values = (row["time"], row["i_a"] * 1e3, row["omega_m"], row["theta_m"] * 1e3)
            f.write(",".join(repr(float(v)) for v in values) + "\n")
    si = json.loads(arcosim("identify", "si.csv", "--json", cwd=workdir).stdout)
    scaled = arcosim(
        "identify",
        "ma.csv",
        "--scale",
        "i_a=0.001",
        "--scale",
        "theta_m=0.001",
        "--json",
        cwd=workdir,
    )
    assert scaled.returncode == 0, scaled.stderr
    converted = json.loads(scaled.stdout)
    for key in ("d_hat", "tau_reac_hat", "theta_hat[1]"):
        assert converted[key] == pytest.approx(si[key], rel=1e-9, abs=1e-15)


@pytest.mark.system
@pytest.mark.slow
def test_identify_takes_a_varying_time_step(workdir) -> None:
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(0.5e-3, 2e-3, 400))
    with open(workdir / "irregular.csv", "w") as f:
        f.write("time,i_a,omega_m,theta_m\n")
        for tk in t:
            f.write(f"{tk},{0.1 * np.sin(5 * tk)},{np.cos(3 * tk)},{np.sin(3 * tk) / 3}\n")
    result = arcosim("identify", "irregular.csv", "--json", cwd=workdir)
    assert result.returncode == 0, result.stderr
    assert all(np.isfinite(v) for v in json.loads(result.stdout).values())


@pytest.mark.system
@pytest.mark.slow
@pytest.mark.parametrize(
    ("content", "phrase"),
    [
        ("", "the file is empty"),
        ("time,i_a,theta_m\n0,0,0\n0.001,0,0\n", "missing column omega_m"),
        (
            "time,i_a,omega_m,theta_m\n0,0,0,0\n0.001,0,0,0\n0.001,0,0,0\n",
            "row 4, column time: 0.001 s does not increase",
        ),
        (
            "time,i_a,omega_m,theta_m\n0,0,0,0\n0.001,nan,0,0\n",
            "row 3, column i_a: nan is not a finite",
        ),
        (
            "time,i_a,omega_m,theta_m\n0,0,0,0\n0.001,0,fast,0\n",
            "row 3, column omega_m: 'fast' is not a number",
        ),
        ("time,i_a,omega_m,theta_m\n0,0,0,0\n", "needs at least two data rows"),
    ],
    ids=["empty", "missing-column", "time-not-increasing", "nan", "not-a-number", "one-row"],
)
def test_bad_logs_get_a_one_line_error(workdir, content, phrase) -> None:
    (workdir / "bad.csv").write_text(content)
    result = arcosim("identify", "bad.csv", cwd=workdir)
    assert result.returncode == 2
    assert phrase in result.stderr, result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1


@pytest.mark.system
@pytest.mark.slow
@pytest.mark.parametrize(
    ("args", "phrase"),
    [
        (["identify", "nowhere.csv"], "nowhere.csv: no such file"),
        (["identify", "x.csv", "--scale", "volts=2"], "--scale 'volts=2'"),
        (["simulate", "--set", "plant.kk[2]=0.2"], "plant has no variable 'kk[2]' (did you mean"),
        (["simulate", "--set", "observer.mode=fast"], "observer.mode takes a whole number"),
        (["simulate", "--set", "g_dist=100"], "name the FMU first"),
        (["simulate", "--set", "plant.i_a=1"], "plant.i_a is an output, not a parameter"),
        (["simulate", "--scenario", "wobble"], "--scenario 'wobble'"),
    ],
)
def test_command_line_mistakes_are_named(workdir, args, phrase) -> None:
    result = arcosim(*args, cwd=workdir)
    assert result.returncode == 2
    assert phrase in result.stderr, result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.system
@pytest.mark.slow
def test_simulate_applies_overrides(workdir) -> None:
    stiff = json.loads(
        arcosim(
            "simulate",
            "--scenario",
            "flexible",
            "--duration",
            "0.5",
            "--set",
            "plant.k[2]=0.5",
            "--set",
            "observer.g_dist=200",
            "--json",
            cwd=workdir,
        ).stdout
    )
    plain = json.loads(
        arcosim(
            "simulate", "--scenario", "flexible", "--duration", "0.5", "--json", cwd=workdir
        ).stdout
    )
    assert stiff["tau_reac_hat"] != plain["tau_reac_hat"]


@pytest.mark.slow
def test_run_scenario_python_api(build_fmus) -> None:
    r = run_scenario(
        SCENARIOS["selfid"],
        fmu_dir=build_fmus(3),
        ideal=True,
        record_observer=["D_m_hat", "f_c_hat"],
    )
    assert r["observer.D_m_hat"][-1] == pytest.approx(2e-5, rel=1e-6)
    assert r["observer.f_c_hat"][-1] == pytest.approx(2e-3, rel=1e-6)


def test_master_records_every_nth_step_and_the_last(build_fmus) -> None:
    folder = build_fmus(3)
    with (
        FmuInstance(folder / "MotorChainPlant.fmu", "p") as p,
        FmuInstance(folder / "ReactionTorqueObserver.fmu", "o") as o,
    ):
        r = cosimulate(
            p, o, [0.3] * 25, 1e-3, ["theta_m_true"], ["k_hat"], IDEAL, {"mode": 1}, record_every=10
        )
    np.testing.assert_allclose(r.time, [0.0, 0.010, 0.020, 0.025])
    assert len(r["plant.theta_m_true"]) == 4 and r["plant.theta_m_true"][-1] > 0


def test_run_scenario_passes_record_every_to_the_master(build_fmus) -> None:
    import dataclasses

    scenario = dataclasses.replace(SCENARIOS["rigid"], duration=0.1)
    r = run_scenario(
        scenario,
        fmu_dir=build_fmus(3),
        record_plant=["twist"],
        record_observer=["k_hat"],
        record_every=40,
    )
    np.testing.assert_allclose(r.time, [0.0, 0.04, 0.08, 0.1])
