"""The linear-model numerics have one home per side, and the two sides agree: the FMU
package's pure Python (``linalg.expm``, ``linalg.hold``, ``riccati.solve_doubling``) and
the host's numpy (``arcosim.identification.fit.linear_model``), on random chains.

Tolerances come from floating-point conditioning, not from a measured margin:

* the hold: scaling and squaring's forward error is a few rounding errors relative to
  ``‖M‖ ‖e^M‖`` (M = [[A, E], [0, 0]] h) per squaring (Higham, SIAM J. Matrix Anal. Appl.
  26, 2005); with at most ~10 squarings here, 64 such errors bound it;
* the Riccati solution: each side rounds its m-term products (m ε relative to X), and
  the equation amplifies a perturbation of it by the norm of its Lyapunov operator's
  inverse, ``κ = ‖(I − A_clᵀ ⊗ A_clᵀ)⁻¹‖₂`` with A_cl the closed loop (the first-order
  perturbation theory of the discrete Riccati equation, Sun 1998).
"""

from __future__ import annotations

import random

import numpy as np
import pytest

from arcosim.fmu.flexchain import linalg, riccati
from arcosim.fmu.flexchain.chain import state_space
from arcosim.fmu.flexchain.control.design import cost_weights
from arcosim.identification.fit import linear_model

EPS = float(np.finfo(float).eps)


def chains(seed: int, count: int):
    """Random motor + chain models (A, b per A of current) and steps, as drives have them."""
    rng = random.Random(seed)
    for _ in range(count):
        n = rng.randint(1, 5)
        J = [10 ** rng.uniform(-5, -2) for _ in range(n)]
        k = [10 ** rng.uniform(-2, 3) for _ in range(n)]
        B = [10 ** rng.uniform(-6, -2) for _ in range(n)]
        A, b = state_space(2.09e-5, 0.0406, 2e-5, J, k, B)
        yield J, k, A, b, rng.choice([2.5e-4, 1e-3, 1e-2])


def riccati_kappa(A: np.ndarray, g: np.ndarray, X: np.ndarray, r: float) -> float:
    """``‖(I − A_clᵀ ⊗ A_clᵀ)⁻¹‖₂`` for the closed loop ``A_cl = A − g K`` of X."""
    K = (g @ X @ A) / (r + g @ X @ g)
    closed = A - np.outer(g, K)
    m = len(A)
    return float(np.linalg.norm(np.linalg.inv(np.eye(m * m) - np.kron(closed.T, closed.T)), 2))


@pytest.mark.parametrize("seed", [1, 2])
def test_the_hold_is_the_same_on_both_sides(seed: int) -> None:
    for _, _, A, b, h in chains(seed, 10):
        E = [[x] for x in b]
        F, G = linalg.hold(A, E, h)
        Fn, Gn = linear_model.hold(np.array(A), np.array(E), h)
        M = np.block([[np.array(A), np.array(E)], [np.zeros((1, len(A) + 1))]]) * h
        size = np.abs(M).sum(axis=1).max()
        scale = np.abs(np.hstack([Fn, Gn])).sum(axis=1).max()
        error = np.abs(np.hstack([np.array(F) - Fn, np.array(G) - Gn])).max()
        assert error <= 64 * EPS * max(1.0, size) * scale, (error, size, scale)
        difference = np.array(linalg.expm(M.tolist())) - linear_model.expm(M.tolist())
        assert np.abs(difference).max() <= 64 * EPS * max(1.0, size) * scale


@pytest.mark.parametrize("seed", [3, 4])
def test_the_riccati_solution_is_the_same_on_both_sides(seed: int) -> None:
    for J, k, A, b, h in chains(seed, 6):
        F, G = linear_model.hold(np.array(A), np.array(b)[:, None], h)
        g = G[:, 0]
        m = len(F)
        # the controller's regulator and a Kalman filter reading the motor angle
        c = np.zeros(m)
        c[0] = 1.0
        cases = [
            (F, g, np.array(cost_weights(2.09e-5, 0.0406, J, k, len(J), 8.0)), 1.0),
            (F.T, c, 1e-6 * np.eye(m), 1e-8),
        ]
        for Am, column, H, r in cases:
            Gm = np.outer(column, column) / r
            X = np.array(riccati.solve_doubling(Am.tolist(), Gm.tolist(), H.tolist()))
            Xn = linear_model.solve_doubling(Am, Gm, H)
            kappa = riccati_kappa(Am, column, Xn, r)
            error = np.abs(X - Xn).max() / np.abs(Xn).max()
            assert error <= m * EPS * kappa, (error, kappa)


def test_a_riccati_not_settled_in_its_steps_is_refused_on_both_sides() -> None:
    one = [[1.0]]  # x ← x + u, cost Σ x² + u²: settles in about six doublings, not one
    with pytest.raises(ValueError, match="did not converge"):
        riccati.solve_doubling(one, one, one, iterations=1)
    with pytest.raises(linear_model.ConvergenceError):
        linear_model.solve_doubling(np.ones((1, 1)), np.ones((1, 1)), np.ones((1, 1)), 1)
