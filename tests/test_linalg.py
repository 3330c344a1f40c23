"""The pure-Python linear algebra against numpy/scipy."""

import numpy as np
import pytest
from scipy.linalg import expm as scipy_expm

from arcosim.fmu.flexchain.linalg import expm, matmul, matvec, solve


@pytest.mark.parametrize("scale", [1e-3, 0.3, 5.0, 400.0])
def test_expm_matches_scipy(scale: float) -> None:
    rng = np.random.default_rng(7)
    a = rng.normal(size=(9, 9)) * scale / 3
    got = np.array(expm(a.tolist()))
    want = scipy_expm(a)
    assert np.max(np.abs(got - want)) <= 1e-12 * max(1.0, np.max(np.abs(want)))


def test_expm_of_oscillator_is_rotation() -> None:
    w, t = 90.0, 0.013
    got = np.array(expm([[0.0, w * t], [-w * t, 0.0]]))
    want = np.array([[np.cos(w * t), np.sin(w * t)], [-np.sin(w * t), np.cos(w * t)]])
    np.testing.assert_allclose(got, want, atol=1e-15)


def test_solve_and_products() -> None:
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(6, 6)), rng.normal(size=(6, 2))
    np.testing.assert_allclose(solve(a.tolist(), b.tolist()), np.linalg.solve(a, b), rtol=1e-12)
    np.testing.assert_allclose(matmul(a.tolist(), b.tolist()), a @ b, rtol=1e-14)
    np.testing.assert_allclose(matvec(a.tolist(), b[:, 0].tolist()), a @ b[:, 0], rtol=1e-14)


def test_solve_refuses_singular_matrix() -> None:
    with pytest.raises(ValueError, match="singular"):
        solve([[1.0, 2.0], [2.0, 4.0]], [[1.0], [1.0]])
