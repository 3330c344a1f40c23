"""The motion experiment's baselines, scores and closed-loop runner, against physics.

Tolerances come from the formulas: the settling time of a decaying sinusoid lies within
half a period before its envelope's crossing; a ZV/ZVD shaper cancels a damped mode's
residual exactly; a rigid inertia under the cascade's velocity P gain closes at ω_v.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from arcosim.experiments.closed_loop import LoadStep, OpenLoop, run_closed_loop
from arcosim.experiments.motion.baselines import (
    CascadeController,
    Shaper,
    cascade_gains,
    cascade_modes,
    cascade_shaper,
    chain_modes,
    smooth_profile,
)
from arcosim.experiments.motion.findings import (
    CONTROLLERS,
    ChainFindings,
    MoveScore,
    done_when,
    move_rows,
)
from arcosim.experiments.motion.metrics import (
    limit_cycle_counts,
    residual_rms,
    settling_time,
)
from arcosim.fmu.flexchain import defaults

BENCH = {"J_mo": defaults.J_M, "k_to": defaults.K_T, "D_m": defaults.D_M}
BENCH.update({f"J[{i}]": defaults.J[i - 1] for i in (1, 2, 3)})
BENCH.update({f"k[{i}]": defaults.K for i in (1, 2, 3)})
BENCH.update({f"B[{i}]": defaults.B for i in (1, 2, 3)})


@pytest.mark.parametrize("sigma, omega", [(0.8, 17.0), (2.0, 30.0), (0.3, 6.0)])
def test_settling_of_a_decaying_sinusoid_is_at_its_envelope(sigma: float, omega: float) -> None:
    """1 + A e^{−σt} cos ωt leaves ±b for the last time within half a period before the
    envelope reaches b, at t* = ln(A/b)/σ."""
    t = np.arange(0.0, 20.0, 1e-4)
    A, band = 0.3, 0.01
    y = 1.0 + A * np.exp(-sigma * t) * np.cos(omega * t)
    crossing = math.log(A / band) / sigma
    settled = settling_time(t, y, 1.0, band)
    assert crossing - math.pi / omega - 1e-4 <= settled <= crossing + 1e-4


def test_settling_never_and_at_once() -> None:
    t = np.linspace(0.0, 1.0, 101)
    assert settling_time(t, 1.0 + 0.1 * np.sin(40 * t) * 0 + 0.02, 1.0, 0.01) == math.inf
    assert settling_time(t, np.ones_like(t), 1.0, 0.01) == 0.0
    with pytest.raises(ValueError, match="band"):
        settling_time(t, t, 1.0, 0.0)


def test_residual_rms_of_an_offset_sine() -> None:
    """rms of c + a sin over whole periods = sqrt(c² + a²/2)."""
    t = np.arange(0.0, 6.0, 1e-3)
    y = 1.0 + 0.002 + 0.004 * np.sin(2 * np.pi * 5 * t)
    assert residual_rms(t, y, 1.0, 2.0) == pytest.approx(math.hypot(0.002, 0.004 / 2**0.5), 1e-3)


def test_limit_cycle_in_counts() -> None:
    """An angle dithering between counts 7 and 9 is 2 counts peak to peak; one held is 0."""
    count = 2 * math.pi / 2000
    t = np.arange(0.0, 4.0, 1e-3)
    dither = np.where(np.sin(40 * t) > 0, 9, 7) * count
    assert limit_cycle_counts(t, dither, 2000, 2.0) == 2.0
    assert limit_cycle_counts(t, np.full_like(t, 5 * count), 2000, 2.0) == 0.0


def _residual(shaper: Shaper, omega: float, zeta: float) -> float:
    """Amplitude of the vibration a mode (ω, ζ) keeps after the shaper's last impulse,
    per unit of what one unshaped impulse leaves (the impulses' phasor sum)."""
    wd = omega * math.sqrt(1 - zeta**2)
    total = sum(
        a * math.exp(zeta * omega * t) * complex(math.cos(wd * t), math.sin(wd * t))
        for t, a in zip(shaper.times, shaper.amplitudes)
    )
    return abs(total) * math.exp(-zeta * omega * shaper.duration)


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.3])
def test_zv_and_zvd_follow_the_formula_and_cancel_the_mode(zeta: float) -> None:
    omega = 20.0
    K = math.exp(-zeta * math.pi / math.sqrt(1 - zeta**2))
    half = math.pi / (omega * math.sqrt(1 - zeta**2))
    zv, zvd = Shaper.zv(omega, zeta), Shaper.zvd(omega, zeta)
    assert zv.times == pytest.approx((0.0, half))
    assert zv.amplitudes == pytest.approx((1 / (1 + K), K / (1 + K)))
    assert zvd.times == pytest.approx((0.0, half, 2 * half))
    assert zvd.amplitudes == pytest.approx(np.array([1, 2 * K, K**2]) / (1 + K) ** 2)
    for shaper in (zv, zvd):
        assert sum(shaper.amplitudes) == pytest.approx(1.0)
        assert _residual(shaper, omega, zeta) < 1e-12
    # ZVD's derivative: 10 % off in frequency it leaves far less than ZV
    assert _residual(zvd, 1.1 * omega, zeta) < 0.25 * _residual(zv, 1.1 * omega, zeta)


def test_shapers_in_series_cancel_both_modes() -> None:
    both = Shaper.zv(10.0, 0.02).then(Shaper.zv(31.0, 0.01))
    assert len(both.times) == 4 and sum(both.amplitudes) == pytest.approx(1.0)
    assert _residual(both, 10.0, 0.02) < 1e-12 and _residual(both, 31.0, 0.01) < 1e-12


def test_cascade_on_a_rigid_inertia_crosses_over_at_its_bandwidth() -> None:
    """Velocity loop k_t (Kv + Ki/s) / (J s): |L(jω_v)| = sqrt(1 + 1/16) with the PI's zero
    at ω_v / 4, and P alone crosses at exactly ω_v."""
    params = {"J_mo": 1e-4, "k_to": 0.05, "J[1]": 4e-4}
    w_v = 12.0
    g = cascade_gains(params, bandwidth=w_v)
    J = 5e-4
    loop = g.k_t * (g.kv + g.ki / (1j * w_v)) / (J * 1j * w_v)
    assert abs(loop) == pytest.approx(math.sqrt(1 + 1 / 16), 1e-12)
    assert g.k_t * g.kv / J == pytest.approx(w_v, 1e-12)
    assert g.kp == pytest.approx(w_v / 4) and g.ki == pytest.approx(g.kv * w_v / 4)


def test_default_bandwidth_is_half_the_first_mode() -> None:
    g = cascade_gains(BENCH)
    assert g.velocity_bandwidth == pytest.approx(0.5 * defaults.MODES[0], 1e-2)
    assert chain_modes(BENCH)[0] == pytest.approx(defaults.MODES, 1e-2)


def test_cascade_modes_of_a_stiff_chain_are_the_rigid_loop() -> None:
    """A chain 10⁴ times stiffer than the bench moves as one inertia: the lowest closed-loop
    pair is the rigid cascade's, the root of the characteristic polynomial of
    J s³ θ + k_t (Kv s + Ki)(s + Kp) θ (velocity filter far above)."""
    stiff = {**BENCH, "D_m": 0.0, **{f"k[{i}]": 1e4 * defaults.K for i in (1, 2, 3)}}
    g = cascade_gains(stiff, bandwidth=8.0)
    g = type(g)(**{**g.__dict__, "velocity_filter": 1e5})
    J = g.inertia
    rigid = np.roots([J, g.k_t * g.kv, g.k_t * (g.ki + g.kv * g.kp), g.k_t * g.ki * g.kp])
    pair = rigid[rigid.imag > 0]
    frequencies, damping = cascade_modes(stiff, g)
    assert frequencies[0] == pytest.approx(abs(pair[0]), 1e-3)
    assert damping[0] == pytest.approx(-pair[0].real / abs(pair[0]), 1e-3)


def test_profile_ends_and_peak_acceleration() -> None:
    t = np.linspace(0.0, 2.0, 20001)
    p, v, a = smooth_profile(t, 2.0, 1.5)
    assert p[0] == 0.0 and p[-1] == 2.0 and v[-1] == 0.0 and a[-1] == 0.0
    assert np.max(a) == pytest.approx(10 / math.sqrt(3) * 2.0 / 1.5**2, 1e-5)
    assert np.max(np.abs(np.gradient(p, t) - v)[1:-1]) < 1e-6
    # the jerk jumps by 60 d/T³ at the ends: a central difference is off by a quarter sample of it
    assert np.max(np.abs(np.gradient(v, t) - a)[1:-1]) < 60 * 2.0 / 1.5**3 * 1e-4 / 4 * 1.01


def _rigid_move(gains, shaper, steps: int = 3000) -> tuple[float, float, CascadeController]:
    """The cascade moving a rigid inertia to 1 rad (exact motion under a held torque): the
    largest distance from its reference (rad), the final angle (rad), the controller."""
    h = 1e-3
    c = CascadeController(gains, 1.0, 10.0, shaper)
    c.reset()
    theta = omega = worst = 0.0
    for k in range(steps):
        acc = gains.k_t * c.step(h, 1.0, 0.0, omega, theta) / gains.inertia
        theta, omega = theta + omega * h + 0.5 * acc * h * h, omega + acc * h
        worst = max(worst, abs(theta - c.reference((k + 1) * h)[0]))
    return worst, theta, c


def test_cascade_with_feedforward_tracks_a_rigid_inertia() -> None:
    """With an unfiltered velocity the fed-forward torque moves a rigid inertia along the
    profile: only the zero-order hold's half-step lag of the torque is left, an angle lag
    of at most h/2 × the peak velocity (1.875 rad/s), which the feedback shrinks. The default
    velocity filter lags (1/(5 ω_v) = 20 ms here), the feedback pushes back, but the PI
    still ends at the target; a shaped move ends there later, by the shaper's duration."""
    params = {"J_mo": 1e-4, "k_to": 0.05, "J[1]": 4e-4}
    g = cascade_gains(params, bandwidth=10.0)
    exact = type(g)(**{**g.__dict__, "velocity_filter": 1e9})
    worst, theta, _ = _rigid_move(exact, None)
    assert worst < 0.5e-3 * 1.875 and theta == pytest.approx(1.0, abs=1e-5)
    for shaper in (None, Shaper.zv(20.0, 0.0)):
        _, theta, c = _rigid_move(g, shaper, 4000)
        assert theta == pytest.approx(1.0, abs=1e-4)
        assert c.reference(1.0 + (shaper.duration if shaper else 0.0))[0] == pytest.approx(1.0)


def test_cascade_shaper_lets_the_bench_settle() -> None:
    """The shaper's modes are the cascade's, all below the velocity filter."""
    g = cascade_gains(BENCH)
    shaper = cascade_shaper(BENCH, g)
    below = [(w, z) for w, z in zip(*cascade_modes(BENCH, g)) if w < g.velocity_filter]
    assert len(shaper.times) == 2 ** len(below) == 8
    half_periods = [math.pi / (w * math.sqrt(1 - z**2)) for w, z in below]
    assert shaper.duration == pytest.approx(sum(half_periods))


def test_runner_holds_the_command_from_the_sample_of_its_step(fmus) -> None:
    """Ideal sensors: the current measured at t_{k+1} is the command computed from the
    sample of t_k (held over the step, zero delay); a load step on the last mass shows as
    its own static twist of the chain."""

    class Echo:
        def __init__(self) -> None:
            self.seen: list[float] = []

        def step(self, h, theta_ref, i_a, omega_m, theta_m):
            self.seen.append(i_a)
            return 0.1 * math.sin(len(self.seen))

    echo = Echo()
    ideal = {"encoder_cpr": 0, "i_noise_std": 0.0}
    run = run_closed_loop(fmus, 3, echo, 0.0, 0.05, plant=ideal)
    assert run.i_a[1:] == pytest.approx(run.i_ref, abs=1e-12)
    assert echo.seen == pytest.approx(run.i_a[:-1].tolist(), abs=0.0)
    assert run.theta.shape == (4, 51)
    # the motor held by a stiff P loop, 1 mN·m on the last mass: each spring twists τ/k
    tau = 1e-3

    class Hold:
        def step(self, h, theta_ref, i_a, omega_m, theta_m):
            return -(2.0 * theta_m + 0.1 * omega_m) / defaults.K_T

    loaded = run_closed_loop(
        fmus, 3, Hold(), 0.0, 3.0, plant={**ideal, "B[1]": 0.02, "B[2]": 0.02, "B[3]": 0.02},
        load=LoadStep(3, 0.0, tau),
    )  # fmt: skip
    twist = loaded.theta[3, -1] - loaded.theta[0, -1]
    assert twist == pytest.approx(3 * tau / defaults.K, rel=1e-3)


def test_open_loop_replays_its_current() -> None:
    o = OpenLoop([0.5, -0.5])
    assert [o.step(1e-3, 0.0, 0.0, 0.0, 0.0) for _ in range(2)] == [0.5, -0.5]


def test_done_when_and_the_table_of_four_rows() -> None:
    good = MoveScore(1.2, 1.4, 2e-4, 0.3, 1.0)
    cascade = MoveScore(math.inf, math.inf, 1.5e-2, 0.3, 0.0)
    slow = MoveScore(2.0, 2.2, 2e-4, 0.3, 2.0)
    assert all(done_when(good, cascade, good).values())
    assert done_when(slow, cascade, good) == {
        "settles": True, "residual": True, "near_bound": False, "no_limit_cycle": False,
    }  # fmt: skip
    found = ChainFindings(n=3, moves=dict.fromkeys(CONTROLLERS, good))
    rows = move_rows({"bench": found})
    assert [r[1] for r in rows] == list(CONTROLLERS) and len(CONTROLLERS) == 4


@pytest.mark.slow
def test_experiment_on_the_bench_has_the_four_rows(fmus) -> None:
    """The experiment's four runs on the bench (designed on the true chain): four rows, the
    cascade ringing (the bench's modes are damped at 0.1 %: never within ±1 %), shaping on
    the cascade's modes cutting the residual at least threefold."""
    from arcosim.experiments.motion.experiment import CHAINS, Runs
    from arcosim.experiments.motion.findings import DISTANCE, score_move

    params = {**BENCH, "f_c": defaults.F_C, "encoder_cpr": 2000, "g_dist": defaults.G_DIST}
    runs = Runs(fmus, CHAINS["bench (n = 3)"], False).four(params)
    found = ChainFindings(n=3, moves={k: score_move(r, DISTANCE, DISTANCE, 2000)
                                      for k, r in runs.items()})  # fmt: skip
    rows = move_rows({"bench (n = 3)": found})
    assert [r[1] for r in rows] == list(CONTROLLERS) == list(runs)
    cascade, shaped = found.moves[CONTROLLERS[0]], found.moves[CONTROLLERS[1]]
    assert cascade.settle_1 == math.inf and cascade.residual > 5e-3
    assert shaped.residual < cascade.residual / 3


def test_runs_give_the_plant_the_encoder_asked_for(fmus) -> None:
    """``Runs(..., encoder_cpr=N)`` puts an encoder of N counts on the plant (every reading
    a whole count of 2π/N), not the bench's 2000 (a 0.1 A push: the motor turns)."""
    from arcosim.experiments.motion.experiment import CHAINS, Runs
    from arcosim.experiments.motion.findings import MOTION_DURATION

    push = OpenLoop(np.full(round(MOTION_DURATION / defaults.STEP), 0.1))
    run = Runs(fmus, CHAINS["bench (n = 3)"], False, encoder_cpr=20000).run(push)
    counts = run.theta_m / (2 * math.pi / 20000)  # whole fine counts, as a 2000 would be too
    assert np.allclose(counts, np.round(counts), atol=1e-6) and np.ptp(counts) > 100
    coarse = run.theta_m / (2 * math.pi / 2000)
    assert not np.allclose(coarse, np.round(coarse), atol=1e-6)


@pytest.mark.parametrize("cpr", ["0", str(2**31)])
def test_bench_control_refuses_an_encoder_it_cannot_run(capsys, cpr: str) -> None:
    """``arcosim bench control --encoder-cpr 0`` (exact) or one past the plant's 32-bit
    integer: one line naming the option, the range and the default."""
    from arcosim.cli import main

    assert main(["bench", "control", "--encoder-cpr", cpr]) == 2
    err = capsys.readouterr().err.strip()
    assert "--encoder-cpr must be 1 … 2147483647" in err and "default 2000" in err
    assert len(err.splitlines()) == 1


def test_a_bench_seed_identifies_designs_and_scores_with_its_encoder(monkeypatch) -> None:
    """``score_seed(..., encoder_cpr=N, distance=d)`` hands N to the identification's log,
    the design and the runs, and d to the runs (stopped there)."""
    from benchmarks import control_accuracy as bench

    seen = {}

    class StoppedError(Exception):
        pass

    def runs(folder, chain, ideal, seed, encoder_cpr, distance):
        seen["runs"] = encoder_cpr, distance
        raise StoppedError

    monkeypatch.setattr(bench, "identify_chain", lambda *a: seen.setdefault("log", a[4]))
    monkeypatch.setattr(bench, "design_parameters", lambda r, i, c: seen.setdefault("design", c))
    monkeypatch.setattr(bench, "Runs", runs)
    with pytest.raises(StoppedError):
        bench.score_seed(
            bench.CHAINS["two-mass, heavy tip"], None, 1, False, encoder_cpr=8192, distance=1.5
        )
    assert seen == {"log": 8192, "design": 8192, "runs": (8192, 1.5)}


@pytest.mark.parametrize("offset", ["1.5", "-2", "nan"])
def test_bench_control_refuses_a_target_offset_past_a_count(capsys, offset: str) -> None:
    """``arcosim bench control --target-offset`` outside −1 … 1 counts (or not a number):
    one line naming the option, the range and the default."""
    from arcosim.cli import main

    assert main(["bench", "control", "--target-offset", offset]) == 2
    err = capsys.readouterr().err.strip()
    assert "--target-offset must be −1 … 1 counts past 1 rad" in err and "default 0" in err
    assert len(err.splitlines()) == 1


def test_the_target_offset_puts_the_target_where_it_says() -> None:
    """``--target-offset`` 0.19 at 2000 counts puts the target half way between two of the
    plant's edges (318.5 counts from the start), and the report says so."""
    from benchmarks import control_accuracy as bench

    distance = bench.target_distance(0.19, 2000)
    assert distance * 2000 / (2 * math.pi) == pytest.approx(318.5, abs=1e-3)
    assert "318.50 counts of the encoder from the start (0.50 count" in bench.geometry(
        distance, 2000
    )
    assert "(0.00 count from the nearer edge)" in bench.geometry(
        bench.target_distance(-0.31, 2000), 2000
    )
