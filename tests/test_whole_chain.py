"""Whole-chain identification (cosim/whole_chain.py): every J_i, k_i, B_i from the
motor side alone."""

from __future__ import annotations

import numpy as np
import pytest

from cosim.errors import UserError
from cosim.output_error import MotorRecord, predict
from cosim.whole_chain import fit_chain, names, split

H = 1e-3
J = (4e-4, 8e-4)
K = (0.3, 0.2)
B = (2e-5, 1.5e-5)


def record(seconds: float) -> MotorRecord:
    """A two-mass chain with unequal springs, driven by a broadband motor angle;
    τ̂ = the model's (noise-free)."""
    t = np.arange(round(seconds / H) + 1) * H
    rng = np.random.default_rng(3)
    theta = sum(
        0.05 / w * np.sin(w * t + rng.uniform(0, 2 * np.pi)) for w in (3, 7, 13, 17, 30, 41, 60)
    )
    clean = MotorRecord(H, theta, np.zeros_like(t), 100.0)
    return MotorRecord(H, theta, predict(clean, J, K, B), 100.0)


def test_every_inertia_stiffness_and_damping_of_an_unequal_chain_is_recovered() -> None:
    """Noise-free: nothing but the motor angle and the reaction torque is given."""
    result = fit_chain(record(10.0), 2)
    assert result.names == names(2) == ["J[1]", "J[2]", "k[1]", "k[2]", "B[1]", "B[2]"]
    fitted_J, fitted_k, fitted_B = split(result.values, 2)
    np.testing.assert_allclose(fitted_J, J, rtol=1e-4)
    np.testing.assert_allclose(fitted_k, K, rtol=1e-4)
    np.testing.assert_allclose(fitted_B, B, rtol=1e-2)
    assert "uniform chain" in result.start_note
    assert set(result.extra["uniform"]) == {"J", "k", "B"}


def test_a_chain_without_masses_is_refused() -> None:
    with pytest.raises(UserError, match="at least one load mass"):
        fit_chain(record(3.0), 0)
