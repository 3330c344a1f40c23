"""The chain tracker (arcosim.fmu.flexchain.chain_tracker) on logs of the independent
drive simulator (benchmarks.simulators.field_sim)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.chain_tracker import (
    EXCITED_SHARE,
    INITIAL_STD,
    PRIOR_STD,
    ChainTracker,
)
from arcosim.fmu.flexchain.dob import Actuator, ReactionObserver
from arcosim.fmu.flexchain.model_observer import NoiseModel
from arcosim.fmu.fmukit.state import restore, snapshot
from benchmarks.simulators import field_sim

H = 1e-3
G = defaults.G_DIST
J2 = tuple(defaults.inertias(2))
K2 = (defaults.K,) * 2
B2 = (defaults.B,) * 2


def moves(t: np.ndarray) -> np.ndarray:
    """Back-and-forth moves: 1 rad in 1 s (a cycloid), 1 s dwell, back (rad)."""
    phase = np.mod(np.asarray(t, float), 4.0)
    up, down = np.clip(phase, 0.0, 1.0), np.clip(phase - 2.0, 0.0, 1.0)

    def cycloid(x: np.ndarray) -> np.ndarray:
        return x - np.sin(2 * np.pi * x) / (2 * np.pi)

    return cycloid(up) - cycloid(down)


def drive(**kw) -> field_sim.Drive:
    base = dict(J_m=defaults.J_M, k_t=defaults.K_T, J=J2, k=K2, B=B2)
    base.update(kw)
    return field_sim.Drive(**base)


def log_of(plant: field_sim.Drive, duration: float, reference=moves, position_gain=5.0):
    loop = field_sim.SpeedLoop(0.1, 0.5, reference, limit=10.0, position_gain=position_gain)
    return field_sim.simulate(plant, H, duration, speed_loop=loop, seed=1)


def tracker(plant: field_sim.Drive, theta0: float = 0.0) -> ChainTracker:
    half = math.pi / plant.counts if plant.counts else 0.0
    noise = NoiseModel(2 * half / math.sqrt(3.0), defaults.TORQUE_NOISE_STD, defaults.TAU_NOISE_STD)
    return ChainTracker(J2, K2, B2, plant.f_c, plant.D_m, G, noise, theta0, half, 60.0, 0.05)


def replay(tr: ChainTracker, plant: field_sim.Drive, log, start: int = 1, stop=None):
    """Feed the log's samples to the tracker through the DOB's torque."""
    dob = ReactionObserver(Actuator(plant.J_m, plant.k_t), G, 0.0, 0.0)
    for i in range(start, stop or len(log.time)):
        dob.step(H, float(log.i_a[i]), float(log.omega_m[i]), float(log.theta_m[i]))
        tr.step(H, dob.drive, float(log.theta_m[i]))


def test_at_rest_it_learns_nothing():
    """At rest the parameters stay, and the start's certainty of the stiffnesses and
    f_c is only forgotten: P grows by 1/λ a step (λ = 1 − h / tracking_time), the
    dampers' stay at the prior."""
    tr = tracker(drive(f_c=defaults.F_C, counts=2000))
    steps = 2000
    for _ in range(steps):
        tr.step(H, 0.0, 0.0)
    assert tr.p == tr.p0
    assert not tr.valid and not tr.alarm
    assert tr.values()[:2] == list(K2)
    grown = INITIAL_STD**2 / (1.0 - H / tr.tracking_time) ** steps
    assert [tr.P[i][i] for i in (0, 1, 4)] == pytest.approx([grown] * 3, rel=1e-9)
    assert [tr.P[i][i] for i in (2, 3, 5)] == [PRIOR_STD**2] * 3
    assert tr.stds()[:2] == pytest.approx([math.sqrt(grown) * k for k in K2], rel=1e-9)


def test_a_long_rest_forgets_the_start():
    """After a few memories at rest every variance is the prior's again."""
    tr = tracker(drive(f_c=defaults.F_C, counts=2000))
    tr.tracking_time = 0.5  # s: 10 memories in the 5 s below
    for _ in range(5000):
        tr.step(H, 0.0, 0.0)
    assert [tr.P[i][i] for i in range(6)] == [PRIOR_STD**2] * 6
    assert not tr.valid


@pytest.mark.slow
def test_gradient_is_the_innovations_derivative():
    """ψ_j, from the sensitivity equations, against a central difference of the
    innovation over 1.5 s of a move (learning off): the difference's own error is of
    order δ² and the neglected ∂K/∂p is zero with the gain held, so 1 % is ample."""
    plant = drive(counts=0)
    log = log_of(plant, 1.5)

    def innovations(j: int, delta: float):
        tr = tracker(plant)
        tr.p[j] += delta
        found: list[tuple[float, float]] = []
        tr.learn = lambda h, e, psi: psi is None or found.append((e, psi[j]))
        replay(tr, plant, log)
        return np.array(found)

    delta = 1e-3  # below REDESIGN_STEP: both runs share one design and gain
    for j in (0, 1, 2, 4):
        plus, minus, base = innovations(j, delta), innovations(j, -delta), innovations(j, 0.0)
        numeric = -(plus[:, 0] - minus[:, 0]) / (2 * delta)
        psi = base[:, 1]
        assert np.linalg.norm(numeric - psi) <= 0.01 * np.linalg.norm(psi), j


@pytest.mark.slow
def test_memory_is_constant_and_state_round_trips():
    plant = drive(f_c=defaults.F_C, counts=2000, current_noise=0.005)
    log = log_of(plant, 3.0)
    tr = tracker(plant)
    replay(tr, plant, log, 1, 1000)
    size = leaves(snapshot(tr))
    copy = restore(json.loads(json.dumps(snapshot(tr))))
    replay(tr, plant, log, 1000, 3000)
    replay(copy, plant, log, 1000, 3000)
    assert leaves(snapshot(tr)) == size  # the same numbers, whatever their digits
    assert snapshot(copy) == snapshot(tr)


def leaves(value: object) -> int:
    """How many numbers, strings and flags a snapshot holds (a count)."""
    if isinstance(value, dict):
        return sum(leaves(v) for v in value.values())
    if isinstance(value, (list, tuple)):
        return sum(leaves(v) for v in value)
    return 1


@pytest.mark.slow
def test_tracks_a_two_mass_chain_in_moves():
    """A healthy two-mass chain in 40 s of position-loop moves with the realistic
    sensors: every k within 3 % (the issue's target), resolved, and σ_k within a few %
    (the prior's 10 % shrinks with the moves' information)."""
    plant = drive(D_m=defaults.D_M, f_c=defaults.F_C, counts=2000, current_noise=0.005)
    log = log_of(plant, 40.0)
    tr = tracker(plant)
    replay(tr, plant, log)
    k, std = tr.values()[:2], tr.stds()[:2]
    assert all(abs(x / y - 1.0) < 0.03 for x, y in zip(k, K2)), k
    assert all(s < 0.03 * y for s, y in zip(std, K2)), std
    assert tr.valid


@pytest.mark.slow
def test_constant_speed_cannot_resolve_friction():
    """At constant speed the Coulomb friction is one more constant torque, like τ_0:
    not resolved, so not valid, and no alarm."""
    plant = drive(D_m=defaults.D_M, f_c=defaults.F_C, counts=2000, current_noise=0.005)
    ramp = lambda t: np.minimum(np.asarray(t, float), 1.0) * 5.0  # noqa: E731 (rad/s)
    log = log_of(plant, 20.0, reference=ramp, position_gain=0.0)
    tr = tracker(plant)
    replay(tr, plant, log)
    assert not tr.valid
    taught = 1.0 / tr.P[4][4] - tr.anchor  # the data's information on f_c, per scale²
    assert taught < 1.0 / (EXCITED_SHARE * PRIOR_STD) ** 2
    assert not tr.alarm
    assert tr.P[4][4] <= PRIOR_STD**2 * (1 + 1e-12)


def drifted(tr: ChainTracker, resolved: tuple[int, ...]) -> ChainTracker:
    """The tracker with k_1 off its commissioning value by twice the threshold and the
    parameters ``resolved`` known to a tenth of the threshold (σ, in units of scale)."""
    tr.p[0] = tr.p0[0] * (1.0 - 2.0 * tr.drift_threshold)
    for i in resolved:
        tr.P[i][i] = (0.1 * tr.drift_threshold) ** 2
    return tr


def test_alarm_waits_for_a_full_memory():
    """A drift twice the threshold, resolved to a twentieth of it, on a tracker whose
    motion taught every stiffness and f_c: no alarm until tracking_time has passed."""
    tr = drifted(tracker(drive(f_c=defaults.F_C)), (0, 1, 4))
    tr.learnt = 0.99 * tr.tracking_time
    tr.judge()
    assert tr.valid and not tr.alarm
    tr.learnt = tr.tracking_time
    tr.judge()
    assert tr.valid and tr.alarm


def test_no_alarm_while_friction_is_not_taught():
    """The same drift, the memory full, but f_c still at its prior (constant speed): not
    valid, and no alarm on the stiffness."""
    tr = drifted(tracker(drive(f_c=defaults.F_C)), (0, 1))
    tr.learnt = tr.tracking_time
    tr.judge()
    assert not tr.valid and not tr.alarm


def test_a_small_viscous_friction_drifts_against_its_floor() -> None:
    """D_m of 2e-5 N·m·s/rad sits below its floor (f_c's scale / VISCOUS_SPEED, 2e-4):
    resolved to a thousandth of the floor, a change of twice the threshold of its value
    is a tenth of the threshold of the floor, no drift; twice the threshold of the
    floor is."""
    tr = tracker(drive(f_c=defaults.F_C, D_m=defaults.D_M))
    m = 2 * len(K2) + 1  # D_m's index
    assert tr.p0[m] < 1.0  # the commissioning value under its floor
    for i in (0, 1, 4, m):
        tr.P[i][i] = 1e-6
    tr.learnt = tr.tracking_time
    tr.p[m] = tr.p0[m] * (1.0 + 2.0 * tr.drift_threshold)
    tr.judge()
    assert tr.valid and not tr.alarm
    tr.p[m] = tr.p0[m] + 2.0 * tr.drift_threshold
    tr.judge()
    assert tr.alarm


def sigma_k1(rho: float, steps: int = 8000) -> float:
    """σ of k_1 (in units of its scale) after ``steps`` least-squares steps on a constant
    regressor and an AR(1) error of unit variance and lag-one correlation ``rho``, with a
    memory of 2 s at 1 ms (40 score blocks of 50 steps)."""
    rng = np.random.default_rng(3)
    tr = ChainTracker(J2, K2, B2, defaults.F_C, defaults.D_M, G, NoiseModel(1e-3, 1e-4, 1.0),
                      0.0, 0.0, 2.0, 0.05)  # fmt: skip
    psi = [1.0] + [0.0] * (len(tr.p) - 1)
    e = 0.0
    for _ in range(steps):
        e = rho * e + math.sqrt(1.0 - rho * rho) * rng.standard_normal()
        tr.learn(H, e, psi)
    return tr.stds()[0] / tr.scale[0]


@pytest.mark.slow
def test_sigma_grows_with_the_scores_correlation():
    """The sandwich σ against the long-run variance: an AR(1) score of ρ = 0.9 carries
    (1 + ρ)/(1 − ρ) = 19 times a white one's variance; batch means over 50-step blocks
    see 19 − 2ρ/(50 (1 − ρ)²)·(1 − ρ⁵⁰) ≈ 15.4 of it, each estimate to about √(2/40)
    (40 blocks' weight in the memory), so the ratio of the two is 15.4 within a factor
    of 1.5 (some 2σ of the pair). The covariance ``P`` alone, for white innovations,
    would give the same σ to both."""
    ratio = (sigma_k1(0.9) / sigma_k1(0.0)) ** 2
    assert 15.4 / 1.5 < ratio < 15.4 * 1.5, ratio
