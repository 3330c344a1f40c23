"""The observer's algorithms on their own (no FMU), against independent numpy code."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import lfilter

from arcosim.fmu.flexchain.dob import Actuator, ReactionObserver, mean_sign
from arcosim.fmu.flexchain.filters import LowPassBank
from arcosim.fmu.flexchain.least_squares import NormalEquations
from arcosim.fmu.flexchain.recursion import ChainRecursion
from arcosim.fmu.flexchain.rigid_identification import SETTLE, RigidChainIdentifier, kappa
from arcosim.fmu.flexchain.self_identification import ActuatorIdentifier

BENCH_J = (5.15299e-4, 5.15299e-4, 6.192707e-4)


def lowpass(x: np.ndarray, g: float, h: float, y0: float = 0.0) -> np.ndarray:
    """G(s) = g/(s+g) with the input held over each step, by scipy."""
    a = math.exp(-g * h)
    return lfilter([1 - a], [1, -a], x, zi=[a * y0])[0]


def test_lowpass_is_exact_for_any_step_sequence() -> None:
    """Unit step through G: 1 − e^{−g t}, whatever the steps taken."""
    f = LowPassBank(50.0, 2)
    t = 0.0
    for h in (1e-3, 7e-3, 2e-4, 0.05, 1e-6, 0.013):
        f.step(h, [1.0, -2.0])
        t += h
        assert f.y[0] == pytest.approx(1 - math.exp(-50.0 * t), rel=1e-12)
        assert f.y[1] == pytest.approx(-2 * (1 - math.exp(-50.0 * t)), rel=1e-12)


@pytest.mark.parametrize(
    ("w0", "w1", "expected"),
    [(2.0, 3.0, 1.0), (-1.0, -4.0, -1.0), (0.0, 0.0, 0.0), (3.0, -1.0, 0.5), (-1.0, 1.0, 0.0)],
)
def test_mean_sign_over_a_step(w0: float, w1: float, expected: float) -> None:
    assert mean_sign(w0, w1) == pytest.approx(expected)


def test_kappa_of_the_bench_is_methods_figure() -> None:
    assert kappa(BENCH_J) == pytest.approx(1.614, abs=5e-4)
    assert kappa([1e-3]) == 1.0


def test_normal_equations_equal_batch_least_squares() -> None:
    rng = np.random.default_rng(4)
    x = rng.normal(size=(500, 4)) * [1.0, 1e3, 1e-3, 5.0]
    y = x @ [0.3, -2e-4, 40.0, 1.5] + rng.normal(size=500) * 0.01
    eq = NormalEquations(4)
    for row, target in zip(x, y):
        eq.add(row, target)
    beta, rcond = eq.solve()
    np.testing.assert_allclose(beta, np.linalg.lstsq(x, y, rcond=None)[0], rtol=1e-9)
    assert 0.0 < rcond <= 1.0
    reduced, _ = eq.solve(columns=(0, 2))
    want = np.linalg.lstsq(x[:, [0, 2]], y, rcond=None)[0]
    np.testing.assert_allclose([reduced[0], reduced[2]], want, rtol=1e-9)
    assert reduced[1] == reduced[3] == 0.0


def test_rigid_identifier_final_estimate_is_the_batch_fit() -> None:
    """Online normal equations = batch least squares on the same rows (no friction)."""
    rng = np.random.default_rng(6)
    h, g, n = 1e-3, 100.0, 3000
    theta = np.cumsum(rng.normal(size=n)) * 1e-3
    omega = rng.normal(size=n)
    torque = rng.normal(size=n) * 1e-2
    ident = RigidChainIdentifier(BENCH_J, g, True, theta0=0.0)
    for k in range(n):
        ident.step(h, torque[k], 0.0, omega[k], theta[k], sticking=False)
    ident.estimate()

    m = sum(BENCH_J)
    i1 = np.cumsum(h * torque)
    i2 = np.cumsum(h * np.r_[0.0, i1[:-1]] + 0.5 * h * h * torque)
    t = h * np.arange(1, n + 1)
    f = [lowpass(x, g, h) for x in (theta, omega, i1, i2, t, np.ones(n), torque)]
    rows = np.column_stack([f[0] - f[3] / m, f[1] - f[2] / m, f[4], f[5]])
    use = t >= SETTLE / g
    beta = np.linalg.lstsq(rows[use], f[6][use], rcond=None)[0]
    assert ident.rows == use.sum()
    assert ident.k == pytest.approx(kappa(BENCH_J) * beta[0], rel=1e-8)
    assert ident.B == pytest.approx(kappa(BENCH_J) * beta[1], rel=1e-6)


def test_actuator_identifier_final_estimate_is_the_batch_fit() -> None:
    rng = np.random.default_rng(8)
    h, g, g_id, n = 1e-3, 100.0, 30.0, 3000
    current = rng.normal(size=n)
    velocity = 20 + rng.normal(size=n)  # always moving
    accel = rng.normal(size=n) * 50
    sgn = np.ones(n)
    d_hat = lowpass(rng.normal(size=n) * 1e-3, g, h)
    ident = ActuatorIdentifier(g, omega_min=5.0, k_to=0.0406, g_id=g_id)
    for k in range(n):
        ident.step(h, current[k], velocity[k], accel[k], sgn[k], d_hat[k])
    ident.estimate()
    x = np.column_stack(
        [lowpass(lowpass(c, g, h), g_id, h) for c in (current, velocity, accel, sgn)]
    )
    y = lowpass(d_hat, g_id, h)
    use = h * np.arange(1, n + 1) >= 5 / g + 5 / g_id - 1e-12
    cols = [1, 2, 3] if ident.rank_deficient else [0, 1, 2, 3]
    beta = np.zeros(4)
    beta[cols] = np.linalg.lstsq(x[use][:, cols], y[use], rcond=None)[0]
    np.testing.assert_allclose(
        [-ident.dkt, ident.D_m, ident.dJm, ident.f_c], beta, rtol=1e-7, atol=1e-15
    )


def test_dob_pairing_recovers_a_constant_load_exactly() -> None:
    """Motor J θ̈ = k_t i − τ with τ constant: d̂ → τ through G, sample by sample."""
    J, kt, tau, g, h = 2e-5, 0.04, 3e-3, 100.0, 1e-3
    dob = ReactionObserver(Actuator(J, kt), g, 0.0, 0.0)
    omega = theta = 0.0
    for k in range(1, 200):
        i = 0.2 + 0.1 * math.sin(0.05 * k)
        accel = (kt * i - tau) / J
        theta += omega * h + 0.5 * accel * h * h
        omega += accel * h
        dob.step(h, i, omega, theta)
        assert dob.d_hat == pytest.approx(tau * (1 - math.exp(-g * k * h)), rel=1e-9)


def test_a_known_heading_is_taken_as_sliding_where_the_encoder_reads_no_count() -> None:
    """A motor crossing less than a count per step reads ω = 0 on most steps, which the
    DOB alone takes for a stuck motor; with its heading given it removes f_c · heading
    (kinetic friction) from the drive torque, as on a step where the encoder moved."""
    f_c, kt, J, h = 2e-3, 0.04, 2e-5, 1e-3
    alone = ReactionObserver(Actuator(J, kt, f_c=f_c), 100.0, 0.0, 0.0)
    told = ReactionObserver(Actuator(J, kt, f_c=f_c), 100.0, 0.0, 0.0)
    i = 0.03  # A: a drive torque (1.2 mN·m) within the friction band
    alone.step(h, i, 0.0, 0.0)
    told.step(h, i, 0.0, 0.0, heading=1.0)
    assert alone.sticking and not told.sticking
    assert told.friction_sign == 1.0
    assert told.torque == pytest.approx(kt * i - f_c, rel=1e-12)
    assert alone.torque == 0.0  # the band's value nearest the previous one


def test_recursion_first_stage_is_the_static_deflection() -> None:
    """B = 0 and a constant torque: θ̂_1 = G[θ_m] − τ/k exactly."""
    rec = ChainRecursion([1e-3], [0.5], [0.0], g_dist=100.0, g_lpf=100.0, theta0=0.0)
    for _ in range(50):
        rec.step(1e-3, 0.02, 1.0)
    expected = (1 - math.exp(-100.0 * 0.05)) * 1.0 - 0.02 / 0.5
    assert rec.theta[0] == pytest.approx(expected, rel=1e-12)
