"""Whole-chain identification on logs of the independent drive simulator
(benchmarks/simulators/field_sim.py): chains, rates, friction, closed loops and loads the project's
plant never made; and the simulator itself, against the project's plant."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from arcosim.fmu.flexchain import defaults, waveforms
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.checks.log_check import check_log
from arcosim.identification.drive_identification import identify_drive
from arcosim.identification.errors import IdentificationError
from arcosim.identification.excitation.design import ExcitationError, design_excitation
from arcosim.identification.fit.kalman import Drive, discrete_drive, filter_riccati
from arcosim.identification.fit.modal_recursion import linear_recursion, output_recursion
from arcosim.identification.fit.whole_chain import split
from arcosim.identification.modes.chain_modes import chain_from_modes, driving_point_modes
from arcosim.identification.records.record import encoder_record, mean_sign
from benchmarks.simulators import field_sim
from tests.field_runs import identify_log

LINES = np.geomspace(3.0, 150.0, 40)
THREE = dict(J=(3e-4, 5e-4, 4e-4), k=(0.25, 0.4, 0.15), B=(1.2e-5, 1.5e-5, 6e-6))


def drive(**kw) -> field_sim.Drive:
    base = dict(J_m=defaults.J_M, k_t=defaults.K_T, D_m=defaults.D_M, f_c=defaults.F_C)
    base.update(THREE)
    base.update(current_noise=0.005)
    base.update(kw)
    return field_sim.Drive(**base)


def fit(d: field_sim.Drive, log: field_sim.Log, friction_given=True, load="none", masses="auto"):
    return identify_log(d, log, friction_given, masses=masses, load=load).choice


def assert_chain(choice, d: field_sim.Drive, rtol: float) -> None:
    """n right, J_i and k_i within ``rtol`` and 4 standard errors, B_i within 4 σ."""
    assert choice.n == d.n
    J, k, B = (np.array(x) for x in split(choice.fit.values, d.n))
    std = choice.fit.std
    for values, truth, offset in ((J, d.J, 0), (k, d.k, d.n), (B, d.B, 2 * d.n)):
        sigma = std[offset : offset + d.n]
        assert np.all(np.abs(values - truth) <= 4 * sigma + 1e-12), (values, truth, sigma)
        if offset < 2 * d.n:
            np.testing.assert_allclose(values, truth, rtol=rtol)


@pytest.mark.slow
def test_the_simulator_agrees_with_the_project_plant(build_fmus) -> None:
    """Bench chain, Coulomb friction with sticking, ideal sensors, 5 s of a multi-sine:
    the two independent simulations agree to 0.1 % of the motion (the sticking
    events are placed differently inside a step: an error of order f_c·h² / J)."""
    from arcosim.experiments.scenarios import Scenario, run_scenario

    current = field_sim.multisine(LINES, 1.0)
    scenario = Scenario("x", "x", current, 5.0, {}, {"mode": 2})
    recording = run_scenario(
        scenario,
        3,
        ideal=True,
        plant={"seed": 1},
        record_plant=["theta_m_true", "theta[3]"],
        fmu_dir=build_fmus(3),
    )
    plant = {k.split(".", 1)[1]: v for k, v in recording.signals.items()}
    d = field_sim.Drive(
        defaults.J_M,
        defaults.K_T,
        defaults.J,
        (defaults.K,) * 3,
        (defaults.B,) * 3,
        defaults.D_M,
        defaults.F_C,
        counts=0,
    )
    log = field_sim.simulate(d, 1e-3, 5.0, current=current)
    assert log.stuck_fraction > 0.02  # sticking happened and was simulated
    for name, column in (("theta_m_true", 0), ("theta[3]", 3)):
        error = plant[name] - log.theta_true[:, column]
        assert np.max(np.abs(error)) < 1e-3 * np.std(plant[name])


def test_a_current_below_the_friction_never_moves_the_motor() -> None:
    d = drive(counts=2**20)
    log = field_sim.simulate(
        d, 1e-3, 1.0, current=lambda t: 0.9 * defaults.F_C / defaults.K_T + 0 * t
    )
    assert log.stuck_fraction == 1.0 and np.all(log.theta_true == 0.0)


def test_fast_recursions_match_the_reference_ones() -> None:
    """Output recursion (real sections) vs the full modal recursion; Riccati by
    doubling vs scipy's, on motor + chain at 4 kHz."""
    d = drive()
    t = np.arange(4001) * 2.5e-4
    i_a = field_sim.multisine(LINES, 3.0)(t)
    actuator = Actuator(d.J_m, d.k_t, 0.0, 0.0, d.D_m, d.f_c)
    record = encoder_record(t, i_a, np.sin(t), actuator, 2000)
    A, Bd = discrete_drive(record, Drive(np.array(d.J), np.array(d.k), np.array(d.B), d.D_m, d.f_c))
    Q = np.outer(Bd[:, 0], Bd[:, 0]) * record.torque_std**2
    R = record.count**2 / 12
    H = np.zeros((len(A), 1))
    H[0, 0] = 1.0
    reference = scipy.linalg.solve_discrete_are(A.T, H, Q + 1e-300 * np.eye(len(A)), [[R]])
    P = filter_riccati(A, Q, R)
    residual = A @ P @ A.T - np.outer(A @ P[:, 0], A @ P[:, 0]) / (P[0, 0] + R) + Q - P
    assert np.max(np.abs(residual)) < 1e-12 * np.max(np.abs(P))  # it solves the equation
    np.testing.assert_allclose(P, reference, rtol=1e-6, atol=1e-9 * np.max(np.abs(P)))
    u = np.vstack([i_a[:-1], np.cos(t[:-1])])
    full = linear_recursion(A, Bd, u, np.zeros(len(A)))[0]
    np.testing.assert_allclose(output_recursion(A, Bd, u), full, atol=1e-12 * np.max(abs(full)))


def test_the_friction_sign_over_a_step_counts_a_reversal_inside_it() -> None:
    velocity = np.array([1.0, 3.0, -1.0, -2.0, 0.0, 0.0, 2.0])
    np.testing.assert_allclose(mean_sign(velocity), [1, 1, 0.5, -1, -1, 0, 1])


@pytest.mark.slow
def test_three_masses_at_4_khz_and_a_refusal_that_names_the_modes() -> None:
    d = drive()
    log = field_sim.simulate(d, 2.5e-4, 10.0, current=field_sim.multisine(LINES, 3.0))
    assert_chain(fit(d, log), d, rtol=5e-3)
    with pytest.raises(
        IdentificationError, match=r"3 excited mode\(s\).*11\.2, 26\.6, 53\.0.*5 masses"
    ):
        fit(d, log, masses=5)


@pytest.mark.slow
def test_closely_spaced_modes_and_a_weakly_coupled_one() -> None:
    """Clamped modes 20, 40, 42 rad/s; the last one with 1/30 of the first's share."""
    p = np.array([20.0, 40.0, 42.0])
    J, k = chain_from_modes(p, p**2 * np.array([0.3, 0.1, 0.01]))
    d = drive(J=tuple(J), k=tuple(k), B=tuple(2 * 0.002 * np.array(k) / 20.0))
    log = field_sim.simulate(d, 1e-3, 20.0, current=field_sim.multisine(LINES, 3.0))
    choice = fit(d, log)
    np.testing.assert_allclose(choice.fit.extra["modes_rad_s"], p, rtol=1e-2)  # the start
    assert_chain(choice, d, rtol=1e-2)


@pytest.mark.slow
def test_friction_fitted_from_k_t_and_J_m_alone() -> None:
    d = drive()
    log = field_sim.simulate(d, 1e-3, 10.0, current=field_sim.multisine(LINES, 3.0))
    choice = fit(d, log, friction_given=False)
    assert_chain(choice, d, rtol=5e-3)
    values, std = choice.fit.as_dict(), choice.fit.std_dict()
    for name, truth in (("D_m", d.D_m), ("f_c", d.f_c)):
        assert abs(values[name] - truth) <= 4 * std[name]
    assert "fitted" in choice.fit.extra["assumptions"]["friction"]
    assert "same ε" in choice.fit.extra["assumptions"]["actuator"]


@pytest.mark.slow
def test_a_pi_speed_loop_with_a_constant_load_torque() -> None:
    """Closed-loop data (the current depends on the encoder's noise) and a load torque
    the loop holds: both in the model, the load estimated."""
    d = drive(load_torque=0.01)
    reference = field_sim.multisine(LINES, 40.0, seed=3, slope=1.0)
    loop = field_sim.SpeedLoop(0.3, 2.25, reference, limit=10.0)
    log = field_sim.simulate(d, 1e-3, 10.0, speed_loop=loop)
    choice = fit(d, log, load="constant")
    assert_chain(choice, d, rtol=5e-3)
    tau, sigma = choice.fit.as_dict()["tau_load"], choice.fit.std_dict()["tau_load"]
    assert abs(tau - 0.01) <= 4 * sigma and sigma < 1e-3


@pytest.mark.slow
def test_a_slowly_varying_load_torque_is_modelled_not_taken_for_the_chain() -> None:
    d = drive(load_sine=(0.01, 0.3))
    log = field_sim.simulate(d, 1e-3, 20.0, current=field_sim.multisine(LINES, 3.0))
    assert_chain(fit(d, log, load="slow"), d, rtol=5e-3)


def test_excite_designs_what_the_excitation_source_plays() -> None:
    e = design_excitation((3.0, 150.0), 3.0, k_t=defaults.K_T, f_c=defaults.F_C)
    assert e.source_parameters == {
        "signal": 1,
        "amplitude": 3.0,
        "frequency": 3.0,
        "frequency_end": 150.0,
        "lines": 40,
        "seed": 1,
    }
    same = [waveforms.multisine(t, 3.0, list(e.frequencies), list(e.phases)) for t in e.time[:50]]
    np.testing.assert_allclose(e.signal[:50], same, atol=1e-12)
    assert np.max(np.abs(e.signal)) <= 3.0 and not e.warnings
    weak = design_excitation((3.0, 150.0), 1.0, k_t=defaults.K_T, f_c=defaults.F_C)
    assert any("stick" in w for w in weak.warnings)
    speed = design_excitation((3.0, 150.0), 3.0, kind="speed", speed_gain=0.3)
    assert speed.source_parameters is None and speed.amplitudes[-1] > 10 * speed.amplitudes[0]
    with pytest.raises(ExcitationError, match=r"0\.3/h"):
        design_excitation((3.0, 500.0), 3.0, h=1e-3)


@pytest.mark.slow
def test_check_tells_a_good_log_from_a_poor_one() -> None:
    d = drive()
    good = field_sim.simulate(d, 1e-3, 20.0, current=field_sim.multisine(LINES, 3.0))
    report = check_log(good.time, good.i_a, good.omega_m, good.theta_m, d.k_t, d.J_m, d.counts)
    assert report.ok, report.text()
    np.testing.assert_allclose(report.modes, driving_point_modes(d.J, d.k)[0], rtol=2e-3)
    poor_current = field_sim.multisine(np.geomspace(3.0, 30.0, 11), 0.5)
    poor = field_sim.simulate(d, 1e-3, 20.0, current=poor_current)
    report = check_log(poor.time, poor.i_a, poor.omega_m, poor.theta_m, d.k_t, d.J_m, d.counts)
    text = report.text()
    assert "counts/s" in text and "excitation: multi-sine:" in text, text  # 11 lines played
    try:  # check is ok exactly when identify fits
        identify_drive(
            poor.time,
            poor.i_a,
            poor.omega_m,
            poor.theta_m,
            k_t=d.k_t,
            J_m=d.J_m,
            encoder_cpr=d.counts,
        )
        assert report.ok, text
    except IdentificationError:
        assert not report.ok, text


@pytest.mark.slow
def test_identify_drive_reads_the_modes_once(monkeypatch) -> None:
    """``check``'s reading of the modes (the friction estimated and taken out first) is
    the one the fit starts from, not made again: the same chain, one reading."""
    from threadpoolctl import threadpool_info

    import arcosim.identification.checks.log_decision as log_decision
    import arcosim.identification.drive_identification as drive_module
    import arcosim.identification.fit.whole_chain as whole_chain

    d = drive()
    log = field_sim.simulate(d, 1e-3, 10.0, current=field_sim.multisine(LINES, 3.0))
    calls = []
    original = whole_chain.first_reading

    def counted(*args, **kwargs):
        calls.append(args[1])
        # the whole call on one BLAS thread: check's reading is the one the fit made
        blas = [p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"]
        assert all(n == 1 for n in blas), blas
        return original(*args, **kwargs)

    monkeypatch.setattr(log_decision, "first_reading", counted)
    monkeypatch.setattr(whole_chain, "first_reading", counted)
    result = identify_log(d, log, friction_given=False)
    assert calls == ["auto"]
    monkeypatch.undo()

    def forgetful(*args, **kwargs):  # the decision without its reading: the fit reads again
        decision = decide_log(*args, **kwargs)
        decision.reading = None
        return decision

    decide_log = log_decision.decide_log
    monkeypatch.setattr(drive_module, "decide_log", forgetful)
    again = identify_log(d, log, friction_given=False)
    np.testing.assert_array_equal(result.choice.fit.values, again.choice.fit.values)
