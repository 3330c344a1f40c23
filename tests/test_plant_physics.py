"""The plant's equations and exact step, checked against independent solutions.

These tests use :class:`arcosim.plant.motorchain.physics.PlantPhysics` directly (no FMU); the
FMU tests check that the built FMU carries the same physics.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from arcosim.plant.motorchain.physics import PlantPhysics

BENCH = {
    "J_m": 2.09e-5,
    "k_t": 0.0406,
    "D_m": 2e-5,
    "J": [5.15299e-4, 5.15299e-4, 6.192707e-4],
    "k": [0.1627] * 3,
    "B": [8.88e-6] * 3,
}


def bench(f_c: float = 0.0, **changes) -> PlantPhysics:
    return PlantPhysics(**{**BENCH, "f_c": f_c, **changes})


def multisine(t: np.ndarray, amplitude: float = 0.3) -> np.ndarray:
    """Current (A) with energy from 5 to 88 rad/s, across all three modes."""
    w = (5.0, 17.0, 31.0, 88.0)
    return amplitude * sum(np.sin(wj * t + j) for j, wj in enumerate(w)) / len(w)


def chain_rhs(J_m, k_t, D_m, J, k, B):
    """Right-hand side of the chain ODE, written independently with numpy."""
    inertia = np.array([J_m, *J])
    n = len(J)
    K, C = np.zeros((n + 1, n + 1)), np.zeros((n + 1, n + 1))
    for i in range(1, n + 1):
        for M, g in ((K, k[i - 1]), (C, B[i - 1])):
            M[i - 1, i - 1] += g
            M[i, i] += g
            M[i - 1, i] -= g
            M[i, i - 1] -= g
    C[0, 0] += D_m

    def rhs(_t, y, current):
        theta, omega = y[: n + 1], y[n + 1 :]
        torque = -K @ theta - C @ omega
        torque[0] += k_t * current
        return np.concatenate([omega, torque / inertia])

    return rhs


def test_multisine_run_matches_solve_ivp() -> None:
    """5 s, h = 2 ms, current held per step: agreement to 1e-6 relative."""
    h, steps = 2e-3, 2500
    current = multisine(np.arange(steps) * h)
    plant = bench()
    rhs = chain_rhs(**BENCH)
    y = np.zeros(8)
    ours, reference = [], []
    for i in current:
        plant.advance(h, float(i), [0.0, 0.0, 0.0])
        ours.append(plant.x[:8])
        sol = solve_ivp(rhs, (0.0, h), y, args=(i,), method="DOP853", rtol=1e-10, atol=1e-14)
        y = sol.y[:, -1]
        reference.append(y)
    ours, reference = np.array(ours), np.array(reference)
    scale = np.max(np.abs(reference), axis=0)
    assert np.max(np.abs(ours - reference) / scale) < 1e-6


@pytest.mark.slow
def test_step_size_does_not_change_the_motion_with_friction() -> None:
    """Exact steps and located friction events: 1 ms and 1/16 ms give one trajectory.

    The slow sine current reverses the motor several times, so the motor sticks and
    breaks away; the events are located inside the steps.
    """
    results = []
    for sub in (1, 16):
        h = 1e-3 / sub
        plant = bench(f_c=2e-3)
        reversals, last = 0, 0.0
        for k in range(2000 * sub):
            held = (k // sub) * 1e-3  # the same current over each millisecond
            plant.advance(h, 0.12 * np.sin(2 * np.pi * 1.5 * held), [0.0] * 3)
            w = plant.x[4]
            reversals += (w * last) < 0 or (w == 0.0) != (last == 0.0)
            last = w
        results.append(np.array(plant.x[:8]))
    assert reversals >= 4
    np.testing.assert_allclose(
        results[0], results[1], rtol=0, atol=1e-9 * np.max(np.abs(results[1]))
    )


def test_sticking_motor_stays_exactly_still() -> None:
    plant = bench(f_c=2e-3)
    for _ in range(1000):
        plant.advance(1e-3, 0.5 * 2e-3 / 0.0406, [0.0] * 3)  # drive torque f_c / 2
    assert plant.x[0] == 0.0 and plant.x[4] == 0.0
    assert all(x == 0.0 for x in plant.x[1:4])


def test_free_motor_spins_up_as_the_friction_model_says() -> None:
    """Detached motor, drive 3 f_c: ω(t) = (T − f_c)/D_m (1 − exp(−D_m t / J_m))."""
    J_m, D_m, f_c, k_t = 2.09e-5, 2e-5, 2e-3, 0.0406
    current = 3 * f_c / k_t
    plant = bench(f_c=f_c, attached=False)
    for _ in range(500):
        plant.advance(1e-3, current, [0.0] * 3)
    t = 0.5
    expected = (k_t * current - f_c) / D_m * (1 - np.exp(-D_m * t / J_m))
    assert plant.x[4] == pytest.approx(expected, rel=1e-9)
    assert plant.reaction_torque() == 0.0


def test_current_loop_is_first_order() -> None:
    """i(t) = i_ref (1 − e^{−w t}); the step mean is its exact average."""
    w, h = 800.0, 1e-3
    plant = bench(current_bandwidth=w)
    plant.advance(h, 1.0, [0.0] * 3)
    assert plant.x[plant.I] == pytest.approx(1 - np.exp(-w * h), rel=1e-12)
    mean = 1 - (1 - np.exp(-w * h)) / (w * h)
    assert plant.step_average_current(h) == pytest.approx(mean, rel=1e-12)


@pytest.mark.parametrize("h", [1e-6, 1e-3, 5e-2])
def test_any_step_size_from_1us_to_50ms_is_stable(h: float) -> None:
    plant = bench(f_c=2e-3)
    steps = max(1, round(0.2 / h))
    for _ in range(min(steps, 5000)):
        plant.advance(h, 0.3, [0.0] * 3)
    assert all(np.isfinite(plant.x))
    # momentum: the chain cannot move faster than the free motor could
    assert abs(plant.x[4]) < 0.3 * 0.0406 / 2e-5
