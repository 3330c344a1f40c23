"""The controller's chain refitted from a move (``move_fit``, ``refined_estimator``): which
samples count, what the fit recovers mass by mass, when it refuses, and the controller's
refitted model on a plant."""

from __future__ import annotations

import math

import pytest

from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.control.controller import shaped_step
from arcosim.fmu.flexchain.control.move_fit import MoveRecord, Sample, fit_chain
from arcosim.fmu.flexchain.control.refined_estimator import RefinedEstimator
from arcosim.fmu.flexchain.load_observer import LoadTorqueObserver
from arcosim.fmu.flexchain.model_observer import NoiseModel
from tests.control_runs import closed_loop

H = 1e-3
NOISE = NoiseModel(theta_noise_std=1e-3, torque_noise_std=1e-3, tau_noise_std=1.5e-3)
TRUE_J = (3e-4, 4e-4, 3e-4)
TRUE_K = (0.15, 0.12, 0.15)
B = (1e-5,) * 3
#: The model's errors, a different one on every J_i and k_i (no pair of common factors
#: on every J_i and every k_i reproduces them).
J_ERR = (1.08, 0.93, 1.05)
K_ERR = (0.92, 1.07, 0.95)


def estimator(J, k) -> LoadTorqueObserver:
    return LoadTorqueObserver(J, k, B, defaults.G_DIST, NOISE, 0.0, len(J))


def move_samples(J, k, duration: float = 0.7, move_time: float = 1.0) -> list[Sample]:
    """τ̂_reac as the chain (J, k) gives it, noise-free, while the motor follows a 1 rad
    shaped step (trusted throughout)."""
    truth = estimator(J, k)
    s, out = list(truth.s), []
    for step in range(1, round(duration / H) + 1):
        theta = shaped_step(step * H / move_time)[0]
        s = truth.predict(H, theta, s)
        truth.u_prev = theta
        out.append(Sample(H, s[-1], theta, True))
    return out


def test_a_sample_counts_once_the_motor_advanced_along_the_heading():
    record = MoveRecord(window=2e-3, trust_after=3e-3)
    path = [0.0, 1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3, 5e-3, 4e-3, 3e-3, 2e-3]
    for theta in path:
        record.step(H, 0.0, theta, heading=1.0)
    trusted = [s.trusted for s in record.samples]
    # advanced over 2 ms from the third sample; trusted once that held 3 ms (the fifth);
    # lost when the motor stops advancing (the eighth: 5e-3 as two samples before)
    assert trusted == [False] * 4 + [True, True, True] + [False] * 4
    standing = MoveRecord(window=2e-3, trust_after=0.0)
    for theta in path:
        standing.step(H, 0.0, theta, heading=0.0)  # no heading: the friction is not known
    assert not any(s.trusted for s in standing.samples)


def test_the_fit_recovers_each_mass_error():
    samples = move_samples(TRUE_J, TRUE_K)
    model_J = tuple(j * e for j, e in zip(TRUE_J, J_ERR))
    model_k = tuple(k * e for k, e in zip(TRUE_K, K_ERR))
    # noise-free data and a prior too wide to pull: the fit is the data's alone
    fit = fit_chain(estimator(model_J, model_k), samples, mass_spread=10.0, common_spread=10.0)
    assert fit is not None and fit.cost_after < 1e-4 * fit.cost_before
    # the factors that take the model to the truth, 1/error on every J_i and k_i, to the
    # iterations' convergence (the model class holds the truth)
    for found, error in zip(fit.J_factors + fit.k_factors, J_ERR + K_ERR):
        assert found * error == pytest.approx(1.0, abs=0.01)
    # with the shipped prior a smooth move's weak data (a cost of a few units of the noise
    # on τ̂_reac) move the model nearer the truth on average, not all the way
    shipped = fit_chain(estimator(model_J, model_k), samples)
    errors = [
        abs(math.log(f * e)) for f, e in zip(shipped.J_factors + shipped.k_factors, J_ERR + K_ERR)
    ]
    given = [abs(math.log(e)) for e in J_ERR + K_ERR]
    assert shipped.cost_after < 0.1 * shipped.cost_before
    assert sum(errors) < sum(given) and max(errors) > 0.01


def test_the_fit_refuses_what_the_data_cannot_support():
    samples = move_samples(TRUE_J, TRUE_K)
    untrusted = [Sample(s.h, s.tau_reac_hat, s.theta_m, False) for s in samples]
    assert fit_chain(estimator(TRUE_J, TRUE_K), untrusted) is None
    # a model three times too stiff, no prior to hold it: the fit goes outside the range
    stiff = tuple(3.0 * k for k in TRUE_K)
    wide = dict(mass_spread=10.0, common_spread=10.0)
    assert fit_chain(estimator(TRUE_J, stiff), samples, **wide) is None


def test_refine_replaces_the_estimator_and_ends_the_record():
    model_J = tuple(j * e for j, e in zip(TRUE_J, J_ERR))
    model_k = tuple(k * e for k, e in zip(TRUE_K, K_ERR))
    refined = RefinedEstimator(estimator(model_J, model_k))
    refined.restart()
    for sample in move_samples(TRUE_J, TRUE_K):
        refined.step(sample.h, sample.tau_reac_hat, sample.theta_m, 1.0)
    before = refined.filter
    fit = refined.refine()
    assert fit is refined.fit and refined.refined
    assert refined.record is None and refined.start is None
    assert refined.filter is not before and refined.belief is fit.belief
    # the factors count from the chain as designed, which was the estimator's
    assert refined.filter.J == pytest.approx([a * f for a, f in zip(model_J, fit.J_factors)])
    assert refined.filter.k == pytest.approx([a * f for a, f in zip(model_k, fit.k_factors)])
    # the refitted estimate follows the truth's state: the fit's model run with the
    # Kalman correction over the move from the move's start
    replayed = estimator(refined.filter.J, refined.filter.k)
    for sample in move_samples(TRUE_J, TRUE_K):
        replayed.step(sample.h, sample.tau_reac_hat, sample.theta_m)
    assert refined.filter.s == pytest.approx(replayed.s, abs=1e-12)
    refined.step(H, 0.0, 0.7, 1.0)  # the record ended: nothing more to refit from
    assert refined.record is None and refined.refine() is None


def test_a_refusal_keeps_the_estimator():
    refined = RefinedEstimator(estimator(TRUE_J, TRUE_K))
    refined.restart()
    for sample in move_samples(TRUE_J, TRUE_K):
        refined.step(sample.h, sample.tau_reac_hat, sample.theta_m, 0.0)  # no heading
    before = refined.filter
    assert refined.refine() is None and refined.filter is before and not refined.refined
    assert refined.belief is None and refined.record is None


#: The four-mass chain of ``arcosim bench control`` (modes from about 10 rad/s).
FOUR = dict(J=(3e-4, 4e-4, 3e-4, 5e-4), k=(0.15, 0.12, 0.15, 0.1), B=(1e-5,) * 4)


@pytest.mark.slow
@pytest.mark.parametrize("a, b", [(1.1, 0.9), (0.9, 1.1)])
def test_the_controller_refines_towards_the_plant(a, b):
    """On the four-mass chain's Python plant (2000-count encoder, 5 mA current noise),
    designed on every J_i × a and every k_i × b (10 % off): after the move the refitted
    model is within 3 % of the plant on every J_i and k_i, a third of the error it was
    designed with."""
    model = dict(FOUR, J=tuple(a * j for j in FOUR["J"]), k=tuple(b * k for k in FOUR["k"]))
    run = closed_loop(FOUR, model, stop=1.0)
    refined = run.extra["controller"].estimator
    assert refined.fit is not None and refined.refined
    found = refined.filter
    for value, true in zip(found.J + found.k, FOUR["J"] + FOUR["k"]):
        assert abs(math.log(value / true)) < 0.03


def test_a_model_that_already_predicts_the_move_is_not_refitted():
    # the truth's own model: its error is the filter's rounding, far below the evidence
    # the fit asks for (a few units of the noise on τ̂_reac)
    samples = move_samples(TRUE_J, TRUE_K)
    assert fit_chain(estimator(TRUE_J, TRUE_K), samples) is None


def test_a_refitted_model_is_kept_on_a_weak_move():
    model_J = tuple(j * e for j, e in zip(TRUE_J, J_ERR))
    model_k = tuple(k * e for k, e in zip(TRUE_K, K_ERR))
    refined = RefinedEstimator(estimator(model_J, model_k))
    strong = move_samples(TRUE_J, TRUE_K, duration=0.7, move_time=0.5)  # a faster move
    refined.restart()
    for sample in strong:
        refined.step(sample.h, sample.tau_reac_hat, sample.theta_m, 1.0)
    first = refined.refine()
    assert first is not None and first.cost_before > defaults.REFINE_AGAIN
    model, belief = refined.filter, refined.belief
    # the next move: the refitted model predicts it within REFINE_AGAIN, so no refit
    refined.restart()
    for sample in move_samples(TRUE_J, TRUE_K):
        refined.step(sample.h, sample.tau_reac_hat, sample.theta_m, 1.0)
    assert refined.refine() is None and refined.filter.J == model.J
    assert refined.belief is belief
