"""The motion and vibration controller's design and its closed loop on the reference plant.

The design (pure Python) is checked against scipy; the closed loops run the Python
reference plant (exact over each step, Coulomb friction with sticking) read by the plant
FMU's sensors (``tests/control_runs.py``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.chain import state_space
from arcosim.fmu.flexchain.control.controller import shaped_step
from arcosim.fmu.flexchain.control.design import (
    DECAY_RATIO,
    design_controller,
    goals,
    hold_discretize,
    regulator_gain,
)
from arcosim.fmu.flexchain.riccati import solve_doubling
from benchmarks.control_accuracy import CHAINS
from tests.control_runs import ACTUATOR, BENCH_2, FIVE, closed_loop, observer_params

H = 1e-3
COUNT = 2 * math.pi / 2000  # one encoder count (rad)
#: `arcosim bench control`'s four-mass chain: 31.7 rad/(N·m) from the motor to the last mass.
FOUR = {key: getattr(CHAINS["four-mass, soft"], key) for key in ("J", "k", "B")}


def _true_loop(design, chain: dict) -> np.ndarray:
    """``F − g K`` of the plant ``chain`` under the design's gain (full state)."""
    A, b = state_space(
        ACTUATOR["J_m"], ACTUATOR["k_t"], ACTUATOR["D_m"], chain["J"], chain["k"], chain["B"]
    )
    F, g = hold_discretize(A, b, H)
    return np.array(F) - np.outer(g, design.K)


def test_doubling_solves_the_regulators_riccati_equation_as_scipy_does() -> None:
    design = design_controller(observer_params(**FIVE), h=H)
    rng = np.random.default_rng(3)
    M = rng.standard_normal((6, 6))
    Q = M @ M.T
    F = np.array(design.F)[:6, :6]
    g = np.array(design.g)[:6]
    K = regulator_gain(F.tolist(), g.tolist(), Q.tolist(), 2.0)
    X = scipy.linalg.solve_discrete_are(F, g[:, None], Q, np.array([[2.0]]))
    K_ref = (g @ X @ F) / (2.0 + g @ X @ g)
    assert np.allclose(K, K_ref, rtol=1e-8, atol=1e-12)
    assert solve_doubling([[1.0]], [[1.0]], [[1.0]])[0][0] == pytest.approx((1 + 5**0.5) / 2)


@pytest.mark.parametrize("chain", [BENCH_2, FIVE], ids=["bench two-mass", "five-mass"])
def test_every_pole_decays_at_the_prescribed_rate(chain: dict) -> None:
    """The shifted regulator: every closed-loop pole, each flexible mode's included,
    inside the circle of radius e^(−α h), α = DECAY_RATIO · ω_c."""
    design = design_controller(observer_params(**chain), h=H)
    poles = np.linalg.eigvals(_true_loop(design, chain))
    alpha = DECAY_RATIO * design.bandwidth
    assert np.abs(poles).max() <= math.exp(-alpha * H) * (1 + 1e-9)


@pytest.mark.parametrize("chain", [BENCH_2, FIVE], ids=["bench two-mass", "five-mass"])
def test_the_gain_stabilizes_every_chain_within_ten_percent(chain: dict) -> None:
    """Every J_i, k_i scaled by independent factors in [0.9, 1.1] (20 seeds) and the two
    corners: the full-state loop with the nominal gain stays stable, and no flexible mode
    loses more than half its designed decay rate."""
    design = design_controller(observer_params(**chain), h=H)
    n = len(chain["J"])
    rng = np.random.default_rng(29)
    factors = [rng.uniform(0.9, 1.1, (2, n)) for _ in range(20)]
    factors += [np.array([[1.1] * n, [0.9] * n]), np.array([[0.9] * n, [1.1] * n])]
    worst = 0.0
    for fj, fk in factors:
        plant = dict(chain, J=tuple(np.array(chain["J"]) * fj), k=tuple(np.array(chain["k"]) * fk))
        worst = max(worst, np.abs(np.linalg.eigvals(_true_loop(design, plant))).max())
    assert worst < math.exp(-0.5 * DECAY_RATIO * design.bandwidth * H)


def test_move_time_and_bandwidth_exactly_one() -> None:
    assert goals(1.0, 0.0) == (1.0, 8.0)
    assert goals(0.0, 4.0) == (2.0, 4.0)
    for bad in ((1.0, 4.0), (0.0, 0.0), (-1.0, 0.0), (math.inf, 0.0)):
        with pytest.raises(ValueError, match=r"move_time .* and bandwidth"):
            goals(*bad)
    with pytest.raises(ValueError, match="control_mass = 3"):
        design_controller(observer_params(**BENCH_2), h=H, control_mass=3)


def test_the_shaped_step_is_smooth_and_ends_at_rest() -> None:
    tau = np.linspace(0.0, 1.0, 2001)
    values = np.array([shaped_step(t) for t in tau])
    assert values[0].tolist() == [0.0, 0.0, 0.0] and values[-1].tolist() == [1.0, 0.0, 0.0]
    assert np.all(np.diff(values[:, 0]) >= 0)
    # the derivatives are the value's (central differences)
    d = np.gradient(values[:, 0], tau)
    assert np.allclose(d[1:-1], values[1:-1, 1], atol=1e-4)


def _check_move(run, target: float = 1.0, counts: int = 2) -> None:
    """A 1 rad move of the last mass: inside ±1 % by 2.5 s and staying there, the motor
    still within ``counts`` counts over the last 2 s."""
    assert run.settling_time(target, 0.01 * target) <= 2.5
    tail = run.time >= run.time[-1] - 2.0
    assert np.ptp(run.theta_m[tail]) <= counts * COUNT + 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0, 1], ids=["sequential", "parallel master"])
def test_a_bench_move_settles_sensorless(delay: int) -> None:
    run = closed_loop(BENCH_2, delay=delay)
    _check_move(run)
    assert run.residual_rms(1.0) <= 2e-3


@pytest.mark.slow
def test_the_bench_holds_the_motor_within_one_count() -> None:
    """The controller's hold on the bench's two-mass chain: the motor within one count over the
    last 2 s and the last mass within 1.2 mrad rms (0.28 measured with the hold's dither,
    0.95 without). With the plain backward difference as the motor's velocity, each hop
    across an edge kicked the command by 0.25 A and the motor held two counts, 1.41 mrad;
    the last crossed edge's velocity reads a dither across one edge as no motion."""
    for delay in (0, 1):
        run = closed_loop(BENCH_2, delay=delay)
        _check_move(run, counts=1)
        assert run.residual_rms(1.0) <= 1.2e-3


@pytest.mark.slow
def test_the_soft_four_mass_chain_holds_the_motor_within_one_count() -> None:
    """At rest the estimators run the hold's gain, which trusts the chain model more than
    τ̂_reac: with the move's gain they passed the noise the dither adds to τ̂_reac to the
    load estimates, the feedback moved the motor with them, and it held two counts (0.40
    mrad rms left; 0.44 now). With one step of delay it holds two either way."""
    run = closed_loop(FOUR)
    tail = run.time >= run.time[-1] - 2.0
    assert np.ptp(run.theta_m[tail]) <= COUNT + 1e-12
    assert run.residual_rms(1.0) <= 1e-3


@pytest.mark.slow
def test_a_target_half_way_between_two_edges_holds_one_count(monkeypatch) -> None:
    """`arcosim bench control`'s two-mass chain with its target 318.5 counts on (half way
    between two of the plant's edges): the dither about the motor's mean reached both
    edges and the motor read two counts at rest (before hold_edge: 6 of 6 runs on this
    plant, noise seeds 1–3, both orders; checked here on seed 1 without the shift); kept
    within 0.3 count of one edge, it holds one. The price is the shift, at most 0.3 count
    (0.94 mrad) at the last mass: the residual stays within the benchmark's criterion for
    this chain, 0.1 × its cascade's 12.5 mrad."""
    two = {key: getattr(CHAINS["two-mass, heavy tip"], key) for key in ("J", "k", "B")}
    target = 318.5 * COUNT
    for delay in (0, 1):
        run = closed_loop(two, target=target, delay=delay)
        _check_move(run, target, counts=1)
        assert run.residual_rms(target) <= 1.25e-3
    monkeypatch.setattr(defaults, "HOLD_EDGE_NEAR", 0.5)  # off: two counts
    run = closed_loop(two, target=target)
    tail = run.time >= run.time[-1] - 2.0
    assert np.ptp(run.theta_m[tail]) > 1.5 * COUNT


@pytest.mark.slow
def test_a_frictionless_drive_holds_the_motor_within_one_count() -> None:
    """Without Coulomb friction (f_c = 0) the plain backward difference's kick at an edge
    is the motor's damping there and holds it on the edge: one count (the last crossed
    edge's velocity, used where friction is cancelled, left it hunting across its count:
    two counts, three with one step of delay)."""
    plant = dict(BENCH_2, f_c=0.0)
    for delay in (0, 1):
        _check_move(closed_loop(plant, delay=delay), counts=1)


@pytest.mark.slow
def test_a_five_mass_move_settles_sensorless() -> None:
    """The five-mass chain's target lies inside a count, and the motor, free of friction
    inside it, hunts across the count's two edges: three counts (0.83 mrad rms left)."""
    run = closed_loop(FIVE)
    _check_move(run, counts=3)
    assert run.residual_rms(1.0) <= 1.2e-3


@pytest.mark.slow
def test_the_sensorless_move_settles_near_the_upper_bound() -> None:
    """The controller's third criterion on the exact model: within 1.3 × the full-state loop's
    settling time. It needs the DOB told the motor's heading during the move: at the
    move's speeds the motor crosses less than a count per 1 ms step, and a DOB that took
    it as stuck left the estimator uncorrected (1.74 × the bound, the last mass's
    estimate 26 mrad off over the move's second half)."""
    run = closed_loop(FIVE)
    bound = closed_loop(FIVE, full_state=True)
    assert run.settling_time(1.0, 0.01) <= 1.3 * bound.settling_time(1.0, 0.01)
    half = (run.time >= 0.5) & (run.time <= 1.0)
    # a few counts (8.5 mrad measured): the encoder's resolution, seen through the DOB
    assert np.max(np.abs(run.theta_hat[half] - run.angles[half, -1])) <= 4 * COUNT


@pytest.mark.slow
@pytest.mark.parametrize(
    ("fj", "fk"), [(1.1, 0.9), (0.9, 1.1)], ids=["model J +10 %, k -10 %", "J -10 %, k +10 %"]
)
def test_the_soft_four_mass_chain_settles_near_the_bound_at_the_corners(fj, fk) -> None:
    """The controller's third criterion on the four-mass chain's corners. It needs the DOB's
    heading weighed against the encoder's edges (``CrossedEdge.heading``). J +10 %,
    k −10 %: as the chain came to rest the motor crept below a count per step, a DOB that
    took it as stuck knew the reaction torque only within ±f_c and kept the estimator's
    own prediction there (1.62 × the bound, 2.46 s against 1.52 s; 0.95 × with the
    edges). J −10 %, k +10 %: within the move the motor turned round while the reference
    still moved, and the DOB told the reference's heading removed friction the wrong way
    (1.89 s against 1.38 s, 1.37 ×; 1.25 × with the edges)."""
    model = dict(FOUR, J=tuple(fj * x for x in FOUR["J"]), k=tuple(fk * x for x in FOUR["k"]))
    run = closed_loop(FOUR, model)
    bound = closed_loop(FOUR, model, full_state=True)
    assert run.settling_time(1.0, 0.01) <= 1.3 * bound.settling_time(1.0, 0.01)


@pytest.mark.slow
def test_the_full_state_upper_bound_settles_faster() -> None:
    run = closed_loop(BENCH_2, full_state=True)
    assert run.settling_time(1.0, 0.005) <= 1.5
    assert run.residual_rms(1.0) <= 2e-4


@pytest.mark.slow
@pytest.mark.parametrize(
    ("fj", "fk"), [(1.1, 0.9), (0.9, 1.1)], ids=["model J +10 %, k -10 %", "J -10 %, k +10 %"]
)
def test_a_bench_move_settles_with_the_model_ten_percent_off(fj: float, fk: float) -> None:
    """The controller designed from a chain whose every J_i is off by one factor and every
    k_i by another (the corners of the identification's ±10 %), run on the true chain."""
    model = dict(
        BENCH_2, J=tuple(fj * x for x in BENCH_2["J"]), k=tuple(fk * x for x in BENCH_2["k"])
    )
    run = closed_loop(BENCH_2, model)
    _check_move(run)
    assert run.residual_rms(1.0) <= 2.5e-3


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0, 1], ids=["sequential", "parallel master"])
@pytest.mark.parametrize(
    ("fj", "fk"), [(1.1, 0.9), (0.9, 1.1)], ids=["model J +10 %, k -10 %", "J -10 %, k +10 %"]
)
def test_the_five_mass_hold_stays_stable_with_the_model_ten_percent_off(
    fj: float, fk: float, delay: int
) -> None:
    """The hold's dither at rest on the chain with the stiffest first spring and the
    lightest first mass (its highest mode at 146 rad/s, the motor against mass 1):
    settled, within a few counts and 1.2 mrad rms (sequential: 6 and 4 counts, 0.57 and
    0.58 mrad). With the dither observer's velocity in the feedback the J +10 %, k −10 %
    corner diverged (the motor over 800 counts, 10 A at the limit)."""
    model = dict(FIVE, J=tuple(fj * x for x in FIVE["J"]), k=tuple(fk * x for x in FIVE["k"]))
    run = closed_loop(FIVE, model, delay=delay)
    _check_move(run, counts=8)
    assert run.residual_rms(1.0) <= 1.2e-3
