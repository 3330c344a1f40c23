"""A flexible link identified from the hub alone: simulated 20 s multi-sine logs (current
noise, encoder counts, Coulomb friction with sticking; benchmarks.simulators.field_sim with the
link's modes), EI, ρA and the first two clamped modes recovered, the tip angle
estimated; and ``arcosim identify --method beam`` end to end.

Tolerances from the physics and the targets: the first two clamped modes within 1 %, EI
and ρA within 5 %, rms(α̂ − α) ≤ 0.1 rms(α) after the first second."""

from __future__ import annotations

import functools
import json

import numpy as np
import pytest

from arcosim.chainfile import read_chain
from arcosim.cli import main
from arcosim.identification.errors import IdentificationError
from arcosim.identification.link.beam_fit import fit_link, fit_modes, modal_of
from arcosim.identification.link.beam_model import modal_model
from arcosim.identification.link.beam_motion import link_assumptions, stiffening_warning, tip_motion
from arcosim.identification.records.record import encoder_record, motor_record
from arcosim.logs import units_path, write_csv
from benchmarks import beam_accuracy as bench


@functools.cache
def simulated(index: int, seed: int = 1) -> bench.BeamLog:
    return bench.simulate(bench.LINKS[index], seed)


def records(log: bench.BeamLog, friction: bool = True):
    c = log.columns
    actuator = bench.actuator(friction)
    motor = motor_record(c["time"], c["i_a"], c["omega_m"], c["theta_m"], actuator, bench.G_DIST)
    encoder = encoder_record(c["time"], c["i_a"], c["theta_m"], actuator, bench.CPR, friction)
    return encoder, motor


@pytest.mark.slow
@pytest.mark.parametrize("index", [0, 1])  # no tip mass (3 modes in band); heavy tip (3)
def test_ei_rhoa_modes_and_tip_from_the_hub(index):
    case, log = bench.LINKS[index], simulated(index)
    encoder, motor = records(log)
    result = fit_link(encoder, motor, case.geometry)
    values, std = result.as_dict(), result.std_dict()
    assert values["EI"] == pytest.approx(case.link.EI, rel=0.05)
    assert values["rhoA"] == pytest.approx(case.link.rhoA, rel=0.05)
    assert std["EI"] < 0.05 * values["EI"] and std["rhoA"] < 0.05 * values["rhoA"]
    np.testing.assert_allclose(
        modal_of(result, case.geometry, 2).frequency, case.modes(2).frequency, rtol=0.01
    )
    fitted = modal_of(result, case.geometry)
    tip = tip_motion(encoder, fitted, bench.D_M, bench.F_C)
    after = log.columns["time"] >= 1.0
    error = tip.alpha_tip[after] - log.alpha_tip[after]
    assert np.sqrt(np.mean(error**2)) <= 0.1 * np.sqrt(np.mean(log.alpha_tip[after] ** 2))


@pytest.mark.slow
def test_without_the_geometry_a_modal_model():
    case, log = bench.LINKS[1], simulated(1)
    encoder, motor = records(log)
    result = fit_modes(encoder, motor, modes=2)
    values = result.as_dict()
    truth = case.modes(2)
    np.testing.assert_allclose([values["omega[1]"], values["omega[2]"]], truth.frequency, rtol=0.01)
    assert values["b[1]"] == pytest.approx(truth.participation[0], rel=0.05)


def test_a_log_without_a_mode_is_refused():
    t = np.arange(5001) * 1e-3
    counts = 2 * np.pi / 2000
    theta = np.floor(0.5 * np.sin(3.0 * t) / counts) * counts
    i_a = -0.5 * 9.0 * np.sin(3.0 * t) * 2e-4 / 0.0406
    log = bench.BeamLog(
        {"time": t, "i_a": i_a, "omega_m": 1.5 * np.cos(3.0 * t), "theta_m": theta}, t, t
    )
    encoder, motor = records(log)
    with pytest.raises(IdentificationError, match="no clamped mode of the link") as refused:
        fit_link(encoder, motor, bench.LINKS[0].geometry)
    assert "masses" not in str(refused.value)


@pytest.mark.slow
def test_identify_method_beam_json_and_out(capsys, tmp_path):
    """``--json`` prints EI, ρA, the hub-locked modes, std and the assumptions;
    ``--out FILE.json`` is a chain file; ``--out FILE.csv`` the tip's motion with units."""
    case, log = bench.LINKS[1], simulated(1)
    path = write_csv(tmp_path / "link.csv", log.columns)
    given = [
        *("--set", f"k_to={bench.K_T}", "--set", f"J_mo={bench.J_M}"),
        *("--set", f"encoder_cpr={bench.CPR}", "--set", f"D_m={bench.D_M}"),
        *("--set", f"f_c={bench.F_C}", "--set", f"g_dist={bench.G_DIST}"),
        *("--set", f"L={case.link.L}", "--set", f"m_tip={case.link.m_tip}"),
        *("--set", f"J_tip={case.link.J_tip}", "--set", f"r_hub={case.link.r_hub}"),
    ]
    report_file = tmp_path / "link.json"
    code = main(
        ["identify", str(path), *given, "--method", "beam", "--json", "--out", str(report_file)]
    )
    out = capsys.readouterr()
    assert code == 0, out.err
    report = json.loads(out.out)
    assert report["EI"] == pytest.approx(case.link.EI, rel=0.05)
    assert report["rhoA"] == pytest.approx(case.link.rhoA, rel=0.05)
    assert report["modes_rad_s"][0] == pytest.approx(case.modes(1).frequency[0], rel=0.01)
    assert {"EI", "rhoA"} <= set(report["std"]) and "model" in report["assumptions"]
    chain = read_chain(report_file)
    assert chain.n == report["equivalent_chain"]["masses"] >= 2
    states = tmp_path / "tip.csv"
    code = main(["identify", str(path), *given, "--method", "beam", "--out", str(states)])
    assert code == 0
    header = states.read_text().splitlines()[0]
    assert header == "time,alpha_tip_hat,w_tip_hat,tau_reac_hat"
    units = json.loads(units_path(states).read_text())
    assert units["alpha_tip_hat"] == "rad" and units["tau_reac_hat"] == "N.m"


def test_identify_method_beam_refuses_a_tip_without_a_length(capsys, tmp_path):
    log = simulated_short()
    path = write_csv(tmp_path / "log.csv", log)
    code = main(["identify", str(path), "--method", "beam", "--set", "m_tip=0.1"])
    assert code == 2 and "--set L=" in capsys.readouterr().err
    code = main(["identify", str(path), "--method", "beam", "--set", "L=-1"])
    assert code == 2 and "must be a number > 0" in capsys.readouterr().err
    code = main(["identify", str(path), "--method", "beam", "--out", str(tmp_path / "x.txt")])
    assert code == 2 and ".json or .csv" in capsys.readouterr().err


def simulated_short() -> dict[str, np.ndarray]:
    t = np.arange(101) * 1e-3
    return {"time": t, "i_a": np.sin(t), "omega_m": np.cos(t), "theta_m": np.sin(t)}


def test_a_hub_fast_against_the_first_mode_is_warned_of():
    """Centrifugal stiffening is outside the linear model: above 0.3 × the first clamped
    mode (hub rad/s against mode rad/s) the report warns, below it stays quiet."""
    slow = 0.29 * 20.0 * np.sin(np.linspace(0, 10, 1000))
    assert stiffening_warning(slow, 20.0) is None
    text = stiffening_warning(-1.1 * slow, 20.0)
    assert text is not None and "centrifugal stiffening" in text and "6.4 rad/s" in text


@functools.cache
def one_mode_log(index: int, seed: int = 1, duration: float = bench.DURATION):
    """A log of link ``index`` whose band holds only its first clamped mode (the lines
    and the band below the second), its band-limited case and g_dist (rad/s)."""
    case, g_dist = bench.one_mode(bench.LINKS[index])
    return bench.simulate(case, seed, duration), case, g_dist


def one_mode_records(index: int, duration: float = bench.DURATION):
    log, case, g_dist = one_mode_log(index, duration=duration)
    c, actuator = log.columns, bench.actuator()
    motor = motor_record(c["time"], c["i_a"], c["omega_m"], c["theta_m"], actuator, g_dist)
    encoder = encoder_record(
        c["time"], c["i_a"], c["theta_m"], actuator, bench.CPR, True, "none", g_dist
    )
    return encoder, motor, case


@pytest.mark.slow
@pytest.mark.parametrize("index", [0, 1, 2])
def test_ei_from_one_mode_with_rhoa_given(index):
    """ρA given, only the first clamped mode in the band: EI within 5 % on each link."""
    encoder, motor, case = one_mode_records(index)
    result = fit_link(encoder, motor, case.geometry, rhoA=case.link.rhoA)
    assert result.extra["detected_modes_rad_s"][0] < case.modes(2).frequency[1] / 2
    assert result.as_dict()["EI"] == pytest.approx(case.link.EI, rel=0.05)


def test_rhoa_given_is_held_and_reported_as_given():
    """A short one-mode log: ρA is no parameter of the fit (no standard error), the
    result and the modal model carry the given value, the assumptions say it is given."""
    encoder, motor, case = one_mode_records(0, duration=6.0)
    rhoA = 1.1 * case.link.rhoA
    result = fit_link(encoder, motor, case.geometry, rhoA=rhoA)
    assert "rhoA" not in result.names and "rhoA" not in result.std_dict()
    assert result.names[0] == "EI" and result.extra["rhoA_given"] == rhoA
    model = modal_of(result, case.geometry)
    truth = bench.Link(result.as_dict()["EI"], rhoA, case.link.L)
    assert model.J_link == pytest.approx(modal_model(truth, 1).J_link, rel=1e-9)
    assert "given: ρA = 0.022 kg/m" in link_assumptions(case.geometry, rhoA)["rhoA"]
    with pytest.raises(IdentificationError, match="rhoA must be > 0"):
        fit_link(encoder, motor, case.geometry, rhoA=-1.0)


def test_one_mode_without_rhoa_is_refused_naming_it(capsys, tmp_path):
    """Without ρA a one-mode record is refused, naming --set rhoA, in the library and on
    the command line, in words of modes and the link (not masses)."""
    encoder, motor, case = one_mode_records(0, duration=6.0)
    with pytest.raises(IdentificationError, match="one clamped mode of the link") as refused:
        fit_link(encoder, motor, case.geometry)
    assert "--set rhoA=M/L" in str(refused.value) and "masses" not in str(refused.value)
    log, _, g_dist = one_mode_log(0, duration=6.0)
    path = write_csv(tmp_path / "link.csv", log.columns)
    given = [
        *("--set", f"k_to={bench.K_T}", "--set", f"J_mo={bench.J_M}"),
        *("--set", f"encoder_cpr={bench.CPR}", "--set", f"D_m={bench.D_M}"),
        *("--set", f"f_c={bench.F_C}", "--set", f"g_dist={g_dist}"),
        *("--set", f"L={case.link.L}"),
    ]
    assert main(["identify", str(path), *given, "--method", "beam"]) == 2
    assert "--set rhoA=M/L" in capsys.readouterr().err
    rhoA = ["--set", f"rhoA={case.link.rhoA}"]
    code = main(["identify", str(path), *given, *rhoA, "--method", "beam", "--json"])
    out = capsys.readouterr()
    assert code == 0, out.err
    report = json.loads(out.out)
    assert report["rhoA"] == case.link.rhoA and report["rhoA_given"] is True
    assert "rhoA" not in report["std"] and "rhoA" in report["assumptions"]
    assert report["EI"] == pytest.approx(case.link.EI, rel=0.05)
