"""A model against a periodic record's own noise (arcosim.identification.fit.periodic_misfit):
the true chain is adequate at the lines, a chain with one inertia 5 % off is not, and
the smallest adequate structure is taken; the measured response is the model's where
the record holds no noise."""

from __future__ import annotations

import numpy as np
import pytest

from arcosim.identification.excitation.spectrum import ExcitationSpectrum, excitation_spectrum
from arcosim.identification.fit.kalman import Drive, discrete_drive
from arcosim.identification.fit.periodic_misfit import (
    Misfit,
    misfit,
    model_response,
    periodic_response,
    smallest_adequate,
)
from arcosim.identification.records.record import EncoderRecord

H, PERIOD, PERIODS = 4e-4, 2500, 12  # 2.5 kHz, 1 s periods, as the motor bench
J_M = 4.8e-3
# D_m sets the rigid motion's time constant, J/D_m = 0.1 s: the transient from rest is
# gone (e^-10) by the end of the first period, which the response leaves out
TRUE = Drive(np.array([4.9e-3]), np.array([560.0]), np.array([0.05]), 0.1, 0.0)


def record(drive: Drive, seed: int, noise: float) -> EncoderRecord:
    """A random-phase multi-sine of torque on harmonics 11 … 250 of the period (1 N·m a
    line), the encoder angle of ``drive`` with white noise of ``noise`` rad."""
    rng = np.random.default_rng(seed)
    n = np.arange(PERIOD * PERIODS)
    harmonics = np.arange(11, 251)
    phases = rng.uniform(0, 2 * np.pi, len(harmonics))
    torque = np.cos(2 * np.pi * np.outer(n / PERIOD, harmonics) + phases).sum(axis=1)
    empty = np.zeros(len(n))
    base = EncoderRecord(H, torque, empty, empty, 1e-9, J_M, 0.0, 0.0, 1e-9)
    A, Bd = discrete_drive(base, drive)
    x, theta = np.zeros(len(A)), np.zeros(len(n))
    for i in range(1, len(n)):
        x = A @ x + Bd[:, 0] * torque[i]
        theta[i] = x[0]
    theta += noise * rng.standard_normal(len(n))
    return EncoderRecord(H, torque, empty, theta, 1e-9, J_M, 0.0, 0.0, 1e-9)


def lines_of(rec: EncoderRecord) -> ExcitationSpectrum:
    """What ``check`` reads the torque as, with a current's noise (1 mN·m)."""
    noise = 1e-3 * np.random.default_rng(0).standard_normal(len(rec.drive))
    return excitation_spectrum(rec.drive + noise, H)


def test_without_noise_the_response_is_the_models() -> None:
    rec = record(TRUE, 0, 0.0)
    response = periodic_response(rec, lines_of(rec))
    assert response is not None and len(response.w) == 240 and response.periods == PERIODS - 1
    model = model_response(rec, TRUE, response.w)
    # what the transient leaves after the first period: e^-10 = 4.5e-5 of it
    np.testing.assert_allclose(response.response, model, rtol=1e-4)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_true_chain_is_adequate_and_one_inertia_off_is_not(seed) -> None:
    """Noise of 1e-6 rad on the angle (the line's response ~1e-5 rad per step at the top of
    the band): the true chain within 3σ of its expectation, J_1 5 % low far beyond."""
    rec = record(TRUE, seed, 1e-6)
    response = periodic_response(rec, lines_of(rec))
    assert misfit(response, model_response(rec, TRUE, response.w)).adequate
    off = Drive(TRUE.J * 0.95, TRUE.k, TRUE.B, TRUE.D_m, 0.0)
    assert not misfit(response, model_response(rec, off, response.w)).adequate


def test_the_smallest_adequate_structure_is_taken_and_none_adequate_says_so() -> None:
    def m(cost: float) -> Misfit:
        return Misfit(cost, 240.0, 290.0, 240)

    assert smallest_adequate({0: m(1e5), 1: m(280.0), 2: m(250.0)}) == (1, 1.0)
    n, level = smallest_adequate({0: m(1e7), 1: m(2.0e6), 2: m(1.9e6), 3: m(1e8)})
    assert n == 1 and level == pytest.approx(1.9e6 / 240.0)
