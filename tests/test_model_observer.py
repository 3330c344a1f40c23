"""The shared chain model (flexchain.driven_chain) and the model-based observer, on
their own, against independent scipy code."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp

from arcosim.fmu.flexchain.driven_chain import continuous_matrices, discretize
from arcosim.fmu.flexchain.model_observer import (
    ModelObserver,
    NoiseModel,
    filter_riccati,
    step_model,
)

J = (5.15299e-4, 5.15299e-4, 6.192707e-4)
K = (0.12, 0.1627, 0.21)
B = (8.88e-6, 2e-5, 5e-6)
H = 1e-3


def motor_angle(t: np.ndarray) -> np.ndarray:
    """A motor angle with energy at the chain's modes (rad)."""
    return 0.3 * np.sin(3.0 * t) + 0.02 * np.sin(17.0 * t + 1) + 0.01 * np.sin(41.0 * t + 2)


def reference(samples: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """States at the samples and step-averaged τ_1, by solve_ivp on the continuous chain
    driven by the motor angle taken linear between the samples."""
    A, E = (np.array(m) for m in continuous_matrices(J, K, B))
    n = len(J)
    x = np.zeros(2 * n)
    x[:n] = samples[0]
    states, torques = [x.copy()], [0.0]
    for k in range(1, len(samples)):
        u0, v = samples[k - 1], (samples[k] - samples[k - 1]) / H

        def rhs(s, z, u0=u0, v=v):
            th = u0 + v * s
            dx = A @ z[:-1] + E @ np.array([th, v])
            tau = K[0] * (th - z[0]) + B[0] * (v - z[n])
            return np.concatenate([dx, [tau]])

        sol = solve_ivp(rhs, (0, H), np.concatenate([x, [0.0]]), rtol=1e-12, atol=1e-14)
        x = sol.y[:-1, -1]
        states.append(x.copy())
        torques.append(sol.y[-1, -1] / H)
    return np.array(states), np.array(torques)


def test_discrete_chain_matches_the_ode_and_the_torque_is_the_momentum_change() -> None:
    t = np.arange(200) * H
    u = motor_angle(t)
    states, torques = reference(u)
    chain = discretize(J, K, B, H)
    Ad, Bd = np.array(chain.Ad), np.array(chain.Bd)
    c, d = (np.array(r) for r in chain.torque_row())
    x = states[0]
    scale = np.max(np.abs(states))
    for k in range(1, len(u)):
        w = np.array([u[k - 1], (u[k] - u[k - 1]) / H])
        assert c @ x + d @ w == pytest.approx(torques[k], rel=1e-7, abs=1e-12)
        x = Ad @ x + Bd @ w
        assert np.max(np.abs(x - states[k])) <= 1e-9 * scale


def test_riccati_by_doubling_matches_scipy() -> None:
    noise = NoiseModel(9.1e-4, 1e-4, 1.5e-3)
    model = step_model(J, K, B, 100.0, noise, H)
    F = np.array(model.F)
    m = len(F)
    G = np.array(model.Gamma)
    s2 = noise.theta_noise_std**2
    Q = G @ np.array([[s2, -s2 / H], [-s2 / H, 2 * s2 / H**2]]) @ G.T
    for i in range(len(J)):
        Q[len(J) + i, len(J) + i] += (noise.torque_noise_std * H / J[i]) ** 2
    Q += 1e-30 * np.eye(m)
    hrow = np.zeros((m, 1))
    hrow[-1, 0] = 1.0
    r = noise.tau_noise_std**2
    P_ref = scipy.linalg.solve_discrete_are(F.T, hrow, Q, np.array([[r]]))
    P = np.array(filter_riccati(model.F, Q.tolist(), r))
    assert np.max(np.abs(P - P_ref)) <= 1e-6 * np.max(np.abs(P_ref))
    K_ref = P_ref[:, -1] / (P_ref[-1, -1] + r)
    assert np.allclose(model.K, K_ref, rtol=1e-5, atol=1e-12)


def test_observer_tracks_the_chain_from_exact_signals() -> None:
    """With the exact motor angle and τ̂_reac = G[τ̄], the estimates are the ODE's
    states (the correction sees no innovation)."""
    t = np.arange(400) * H
    u = motor_angle(t)
    states, torques = reference(u)
    a = math.exp(-100.0 * H)
    tau_hat = 0.0
    obs = ModelObserver(J, K, B, 100.0, NoiseModel(1e-3, 1e-4, 1e-3), u[0])
    scale = np.max(np.abs(states[:, :3] - u[:, None]))
    for k in range(1, len(u)):
        tau_hat = a * tau_hat + (1 - a) * torques[k]
        obs.step(H, tau_hat, u[k])
        assert abs(obs.innovation) < 1e-9
        assert np.max(np.abs(np.array(obs.theta) - states[k, :3])) <= 1e-7 * scale
        assert np.max(np.abs(np.array(obs.omega) - states[k, 3:])) <= 1e-6 * np.max(
            np.abs(states[:, 3:])
        )


@pytest.mark.slow
def test_observer_corrects_a_wrong_start() -> None:
    """Started with mass 1 displaced, the innovation pulls the estimate back."""
    t = np.arange(3000) * H
    u = motor_angle(t)
    states, torques = reference(u[:3000])
    a = math.exp(-100.0 * H)
    obs = ModelObserver(J, K, B, 100.0, NoiseModel(1e-4, 1e-3, 1e-4), u[0])
    obs.s[0] += 0.01  # 10 mrad wrong on mass 1
    tau_hat = 0.0
    errors = []
    for k in range(1, len(u)):
        tau_hat = a * tau_hat + (1 - a) * torques[k]
        obs.step(H, tau_hat, u[k])
        errors.append(abs(obs.theta[0] - states[k, 0]))
    assert errors[-1] < 0.1 * errors[0]


def test_discretization_is_cached_per_step_size() -> None:
    obs = ModelObserver(J, K, B, 100.0, NoiseModel(1e-3, 1e-4, 1e-3), 0.0)
    first = obs.model(H)
    assert obs.model(H) is first
    assert obs.model(2 * H) is not first
