"""The load torque observer (flexchain.load_observer) on its own, against an independent
exact simulation of the chain (scipy's matrix exponential): with exact signals its
error follows its own closed-loop dynamics, so it converges to the applied torque as
fast as those dynamics say; a torque on another mass shows as the same torque (the
static sum), and opposite torques on two masses do not show at all."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp
from scipy.signal import butter, cont2discrete

from arcosim.fmu.flexchain.chain import spring_matrix
from arcosim.fmu.flexchain.load_observer import (
    SMOOTHING_RATIO,
    LoadTorqueObserver,
    load_column,
    load_step_model,
)
from arcosim.fmu.flexchain.model_observer import NoiseModel
from arcosim.fmu.fmukit.state import restore, snapshot
from tests.test_model_observer import B, H, J, K, motor_angle

#: The chain of tests/test_model_observer.py with about 5 % damping, so a torque's
#: ringing dies within seconds.
B_DAMPED = (1.5e-3, 1.5e-3, 1.5e-3)
G_DIST = 100.0
NOISE = NoiseModel(2 * math.pi / 2000 / math.sqrt(12), 1e-4, 1.5e-3)
D = 2.6e-3  # N·m: a tenth of the bench drive's peak torque under a 1 A multi-sine


class ExactChain:
    """The chain driven by a motor angle linear over each step and torques held over it,
    stepped exactly (scipy.linalg.expm of the augmented continuous system); returns
    states and the step mean of spring 1's torque. Independent of flexchain's model."""

    def __init__(self, J, k, B, h) -> None:
        n = len(J)
        Kf, Cf = np.array(spring_matrix(k)), np.array(spring_matrix(B))
        Minv = np.diag(1.0 / np.array(J))
        m = 2 * n + 2 + n + 1  # x, θ_m, v, τ_ext (n), ∫τ_1
        A = np.zeros((m, m))
        A[:n, n : 2 * n] = np.eye(n)
        A[n : 2 * n, :n] = -Minv @ Kf[1:, 1:]
        A[n : 2 * n, n : 2 * n] = -Minv @ Cf[1:, 1:]
        A[n : 2 * n, 2 * n] = -Minv @ Kf[1:, 0]
        A[n : 2 * n, 2 * n + 1] = -Minv @ Cf[1:, 0]
        A[n : 2 * n, 2 * n + 2 : 3 * n + 2] = Minv
        A[2 * n, 2 * n + 1] = 1.0
        A[-1, 0], A[-1, n], A[-1, 2 * n], A[-1, 2 * n + 1] = -k[0], -B[0], k[0], B[0]
        self.n, self.h, self.X = n, h, scipy.linalg.expm(A * h)

    def run(self, u: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """States (N, 2n) and step-mean τ_1 (N,) for motor angles ``u`` (N,) and the
        torques over the step ending at each sample ``tau`` (N, n; row 0 unused)."""
        n = self.n
        x = np.zeros(2 * n)
        x[:n] = u[0]
        states, torques = [x.copy()], [0.0]
        for j in range(1, len(u)):
            z = np.concatenate([x, [u[j - 1], (u[j] - u[j - 1]) / self.h], tau[j], [0.0]])
            z = self.X @ z
            x = z[: 2 * n]
            states.append(x.copy())
            torques.append(z[-1] / self.h)
        return np.array(states), np.array(torques)


def observe(obs: LoadTorqueObserver, u: np.ndarray, torques: np.ndarray) -> np.ndarray:
    """Feed τ̂_reac = G[τ̄_1] and θ_m; return the Kalman d̂ and the output, shape (N, 2)."""
    a = math.exp(-G_DIST * H)
    tau_hat, out = 0.0, [(0.0, 0.0)]
    for j in range(1, len(u)):
        tau_hat = a * tau_hat + (1 - a) * torques[j]
        obs.step(H, tau_hat, u[j])
        out.append((obs.s[2 * obs.n], obs.tau_load))
    return np.array(out)


def test_load_column_matches_the_ode() -> None:
    """b_d (and the chain's response to θ_m) against solve_ivp over a few steps."""
    n = len(J)
    model = load_step_model(J, K, B, G_DIST, NOISE, H, 3, 5.0)
    F = np.array(model.F)
    b_d = np.array(load_column(J, K, B, H, 3))
    assert np.allclose(F[: 2 * n, 2 * n], b_d, rtol=0, atol=1e-15)
    Minv = 1.0 / np.array(J)
    Kf, Cf = np.array(spring_matrix(K)), np.array(spring_matrix(B))

    def rhs(_, z):
        th, om = z[:n], z[n:]
        full_th, full_om = np.concatenate([[0.0], th]), np.concatenate([[0.0], om])
        acc = Minv * (-(Kf @ full_th)[1:] - (Cf @ full_om)[1:] + np.array([0.0, 0.0, 1.0]))
        return np.concatenate([om, acc])

    sol = solve_ivp(rhs, (0, H), np.zeros(2 * n), rtol=1e-12, atol=1e-16)
    assert np.allclose(sol.y[:, -1], b_d, rtol=1e-8, atol=1e-16)


def predicted_error(model, steps: int) -> np.ndarray:
    """d − d̂ after a unit step in the torque, by the filter's own error dynamics
    e_k = (I − K H) F e_{k−1}, entering as (I − K H) g (g: a unit increment of d)."""
    F, Kv = np.array(model.F), np.array(model.K)
    m, n = len(F), (len(F) - 2) // 2
    IKH = np.eye(m)
    IKH[:, -1] -= Kv
    g = np.zeros(m)
    g[: 2 * n] = F[: 2 * n, 2 * n]
    g[2 * n] = 1.0
    g[-1] = F[-1, 2 * n]
    A = IKH @ F
    e = IKH @ g
    out = [e[2 * n]]
    for _ in range(steps - 1):
        e = A @ e
        out.append(e[2 * n])
    return np.array(out)


@pytest.mark.parametrize("load_mass", [1, 3])
def test_estimate_follows_its_error_dynamics_and_converges(load_mass: int) -> None:
    """Exact signals, torque D on the estimated mass from t = 0.5 s: d̂ − D equals the
    filter's predicted error to 1e-9 of D (two exact discretizations agree to rounding),
    and the output equals the second-order low-pass of the prediction (scipy's own ZOH
    discretization); it stays within 1e-3 of D from when the prediction says it does."""
    n, bandwidth = len(J), 5.0
    t = np.arange(8001) * H
    u = motor_angle(t)
    tau = np.zeros((len(t), n))
    start = 500
    tau[start:, load_mass - 1] = D
    _, torques = ExactChain(J, K, B, H).run(u, tau)
    obs = LoadTorqueObserver(J, K, B, G_DIST, NOISE, u[0], load_mass, bandwidth)
    out = observe(obs, u, torques)
    model = obs.model(H)
    e = D * predicted_error(model, len(t) - start)
    assert np.max(np.abs((D - out[start:, 0]) - e)) <= 1e-9 * D
    assert np.all(np.abs(out[:start, 0]) <= 1e-9 * D)  # no torque, no estimate
    w = SMOOTHING_RATIO * bandwidth
    bs, as_ = butter(2, w, analog=True)
    Ad, Bd, *_ = cont2discrete(
        (np.array([[0, 1], [-as_[2], -as_[1]]]), np.array([[0], [bs[-1]]]), [[1, 0]], [[0]]),
        H,
        "zoh",
    )
    z, smooth = np.zeros(2), []
    for d_hat in D - e:
        z = Ad @ z + Bd[:, 0] * d_hat
        smooth.append(z[0])
    assert np.max(np.abs(out[start:, 1] - smooth)) <= 1e-9 * D
    settled = np.nonzero(np.abs(np.array(smooth) - D) > 1e-3 * D)[0][-1] + 1
    assert settled < len(t) - start - 1000  # the prediction settles well within the run
    assert np.all(np.abs(out[start + settled :, 1] - D) <= 1e-3 * D + 1e-9 * D)


def damped_run(load: dict[int, float], load_mass: int, seconds: float = 20.0) -> np.ndarray:
    """Exact signals of the damped chain with ``load`` (mass → torque, N·m) from 0.5 s;
    the output of an estimator set to ``load_mass``, after checking that its slowest
    closed-loop mode has died out by the end (then rounding is all that is left)."""
    n = len(J)
    t = np.arange(round(seconds / H) + 1) * H
    u = motor_angle(t)
    tau = np.zeros((len(t), n))
    for mass, value in load.items():
        tau[500:, mass - 1] = value
    _, torques = ExactChain(J, K, B_DAMPED, H).run(u, tau)
    obs = LoadTorqueObserver(J, K, B_DAMPED, G_DIST, NOISE, u[0], load_mass)
    out = observe(obs, u, torques)[:, 1]
    # A torque on another mass is, after the step, a trajectory of the model (a constant
    # torque on load_mass plus a free motion of the chain: the same modes), so the error
    # obeys the filter's closed loop e_k = A e_{k−1}, ‖A^k‖ ≤ κ(V) ρ^k.
    model = obs.model(H)
    F, Kv = np.array(model.F), np.array(model.K)
    A = F.copy()
    A -= np.outer(Kv, F[-1])
    eigenvalues, V = np.linalg.eig(A)
    rho = np.max(np.abs(eigenvalues))
    assert np.linalg.cond(V) * rho ** (len(t) - 600) < 1e-12
    return out


def test_a_constant_torque_on_another_mass_shows_as_the_same_torque() -> None:
    """Observability: every load mass has static gain −1 to τ_reac, so an estimator set
    to mass 3 meeting D on mass 2 ends at D (to rounding, see damped_run)."""
    out = damped_run({2: D}, 3)
    assert abs(out[-1] - D) <= 1e-9 * D
    assert np.max(np.abs(out - D)[1000:5000]) > 0.01 * D  # it did not get there at once


def test_opposite_torques_on_two_masses_do_not_show() -> None:
    """Observability: +D on mass 1 and −D on mass 3 only twist springs 2 and 3, which the
    motor never sees once the chain has settled: the estimate ends at 0."""
    out = damped_run({1: D, 3: -D}, 3)
    assert abs(out[-1]) <= 1e-9 * D
    assert np.max(np.abs(out)) > 0.01 * D  # the transient did show something


def test_state_snapshot_continues_bit_identically() -> None:
    t = np.arange(1200) * H
    u = motor_angle(t)
    tau = np.zeros((len(t), 3))
    tau[100:, 2] = D
    _, torques = ExactChain(J, K, B, H).run(u, tau)
    obs = LoadTorqueObserver(J, K, B, G_DIST, NOISE, u[0], 3)
    observe(obs, u[:600], torques[:600])
    copy = restore(snapshot(obs))
    a = observe(obs, u[599:], torques[599:])
    b = observe(copy, u[599:], torques[599:])
    assert np.array_equal(a, b)
    assert a[-1, 1] != 0.0


@pytest.mark.parametrize(
    ("kwargs", "phrase"),
    [({"load_mass": 0}, "load_mass = 0"), ({"load_mass": 4}, "load_mass = 4")],
)
def test_bad_load_mass_is_refused(kwargs, phrase) -> None:
    with pytest.raises(ValueError, match=phrase):
        LoadTorqueObserver(J, K, B, G_DIST, NOISE, 0.0, **kwargs)
