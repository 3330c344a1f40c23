"""Honest uncertainty of the friction fit: the standard errors' bandwidth
counts a small correlation the innovations keep over many lags, and a friction term the
rule leaves out widens the kept parameters by what it moves them on the opening where
the rule compared the forms. Each test is numpy-only and fast."""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter
from threadpoolctl import threadpool_limits

from arcosim.identification.fit.newey_west import (
    decorrelation_lag,
    newey_west_covariance,
    significance_lag,
)
from arcosim.identification.fit.output_error import ParameterFit
from arcosim.identification.fit.structure_choice import carry_over, with_form_shift


def _regression(seed: int) -> tuple[np.ndarray, np.ndarray, float]:
    """A slow regressor, its least-squares residual and the estimate's true σ: the
    noise white plus a slow AR(1) part (φ 0.97) of 7 % of its variance: its
    autocorrelation 0.06 over dozens of lags, as the innovations of the three-mass fit."""
    rng = np.random.default_rng(seed)
    n, phi = 20000, 0.97
    x = lfilter([1.0], [1.0, -0.95], rng.standard_normal(n))
    slow = lfilter([1.0], [1.0, -phi], rng.standard_normal(n)) * np.sqrt(0.07 * (1 - phi**2))
    e = rng.standard_normal(n) + slow
    beta = float(x @ e / (x @ x))
    # Var(β̂ | x) = Σ_t Σ_u x_t x_u γ(t − u) / (Σ x²)², γ(0) = 1.07, γ(k) = 0.07 φ^|k|
    lags = np.arange(1, 400)
    products = np.fft.irfft(np.abs(np.fft.rfft(x, 2 * n)) ** 2)[lags]  # Σ x_t x_{t+k}
    cross = float(np.sum(2.0 * 0.07 * phi**lags * products))
    true_sigma = np.sqrt(1.07 * float(x @ x) + cross) / float(x @ x)
    return x[:, None], e - beta * x, float(true_sigma)


def test_the_bandwidth_counts_a_small_persisting_correlation() -> None:
    """On 20 000 samples a correlation of 0.06 is 4× its sampling error 2/√N: the
    σ's bandwidth runs until it is noise, and the σ comes within 15 % of the truth,
    where the first fall below 0.1 (lag 3) leaves it ≥ 20 % short."""
    with threadpool_limits(limits=1, user_api="blas"):  # small products: one thread
        for seed in (1, 2, 3):
            _check_bandwidth(seed)


def _check_bandwidth(seed: int) -> None:
    x, residual, truth = _regression(seed)
    short, long = decorrelation_lag(residual, 1), significance_lag(residual, 1)
    assert long > short
    sigma_short = np.sqrt(newey_west_covariance(x, residual, short)[0, 0])
    sigma_long = np.sqrt(newey_west_covariance(x, residual, long)[0, 0])
    assert sigma_short < 0.8 * truth, (seed, sigma_short / truth)
    assert abs(sigma_long / truth - 1.0) < 0.15, (seed, sigma_long / truth)


def test_white_innovations_keep_a_short_bandwidth() -> None:
    residual = np.random.default_rng(5).standard_normal(20000)
    assert significance_lag(residual, 1) <= 9


def _fit(values: dict[str, float], std: float = 1e-7) -> ParameterFit:
    v = np.array(list(values.values()))
    return ParameterFit(list(values), v, np.full(len(v), std), v, "", 0.0, 1.0, 3, 0)


def test_a_left_out_term_widens_sigma_by_its_shift_on_the_opening() -> None:
    """The whole record's fit of both terms stuck with D_m at 0 and B_1 biased (so the
    Coulomb-only fit agrees with it): the opening's two forms, from one start, show what
    leaving D_m out moves B_1 by, and that widens its σ."""
    final = _fit({"B[1]": 9.79e-5, "f_c": 2.046e-3})
    stuck = _fit({"B[1]": 9.79e-5, "D_m": 2e-10, "f_c": 2.046e-3})
    opening_both = _fit({"B[1]": 9.33e-5, "D_m": 2.9e-5, "f_c": 2.0e-3})
    opening_coulomb = _fit({"B[1]": 1.013e-4, "f_c": 2.05e-3})
    with_form_shift(final, stuck, opening_both, opening_coulomb)
    sigma = final.std_dict()
    assert abs(9.79e-5 - 8.91e-5) <= 2 * sigma["B[1]"]  # the truth covered
    assert final.extra["form_shift"]["B[1]"] == (1.013e-4 - 9.33e-5)
    alone = _fit({"B[1]": 9.79e-5, "f_c": 2.046e-3})
    with_form_shift(alone, stuck)  # the whole record's pair alone: no widening
    assert alone.std_dict()["B[1]"] < 1.1e-7


def test_the_sign_shift_survives_a_load_refit() -> None:
    """The friction sign's widening (square wave, seed 17: one more smoothing moved f_c
    by 2.1σ) is carried onto the fit refitted with a load torque."""
    result = _fit({"D_m": 2.0e-5, "f_c": 2.0198e-3}, std=9.3e-6)
    result.extra["sign_shift"] = {"f_c": -1.98e-5}
    final = _fit({"D_m": 2.0e-5, "f_c": 2.0198e-3, "tau_load": 1e-4}, std=9.3e-6)
    carry_over(final, result, 3)
    assert abs(2.0198e-3 - 2e-3) <= 2 * final.std_dict()["f_c"]  # the truth covered
    assert final.extra["sign_shift"] == {"f_c": -1.98e-5}
    assert "form_shift" not in final.extra
