"""The linear-model numerics on numpy: the matrix exponential, the zero-order hold with
its input integral, and the discrete Riccati equation by doubling.

The host's twin of the FMU package's pure-Python ones (:func:`arcosim.fmu.flexchain.linalg.
expm`, :func:`arcosim.fmu.flexchain.linalg.hold`, :func:`arcosim.fmu.flexchain.riccati.
solve_doubling`): the same equations, solved with numpy and scipy where the fits call
them hundreds of times; ``tests/test_linear_model.py`` holds the two sides equal.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg


class ConvergenceError(ValueError):
    """The doubling iteration did not settle within its steps (not a singular matrix,
    which numpy reports as ``LinAlgError``)."""


def expm(a: list[list[float]]) -> list[list[float]]:
    """``e^a`` by scipy, on and to lists of lists: the exponential the pure-Python
    discretizations take offline (:func:`arcosim.fmu.flexchain.driven_chain.discretize`).

    Parameters
    ----------
    a : list of list of float
        Shape ``(m, m)``, dimensionless (the step is in it).

    Returns
    -------
    list of list of float
        ``e^a``, shape ``(m, m)``.

    Examples
    --------
    >>> expm([[0.0, 1.0], [0.0, 0.0]])
    [[1.0, 1.0], [0.0, 1.0]]
    """
    return scipy.linalg.expm(np.asarray(a)).tolist()


def hold(A: np.ndarray, E: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """The zero-order hold: ``s ← F s + Γ w`` for ``ṡ = A s + E w`` with w held over a step.

    ``F = e^{A h}`` and ``Γ = ∫_0^h e^{A t} dt · E`` from one exponential of the augmented
    ``[[A, E], [0, 0]] h`` (Van Loan 1978), as
    :func:`arcosim.fmu.flexchain.linalg.hold` computes them in pure Python.

    Parameters
    ----------
    A : ndarray
        Shape ``(m, m)``, per second.
    E : ndarray
        Shape ``(m, p)``, the state's rate per unit of each input.
    h : float
        Step (s).

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``F``, shape ``(m, m)``, and ``Γ``, shape ``(m, p)``.

    Examples
    --------
    >>> F, G = hold(np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]), 0.1)
    >>> np.round(G[:, 0], 15).tolist()
    [0.005, 0.1]
    """
    m, p = E.shape
    augmented = np.zeros((m + p, m + p))
    augmented[:m, :m] = A
    augmented[:m, m:] = E
    X = scipy.linalg.expm(augmented * h)
    return X[:m, :m], X[:m, m:]


def solve_doubling(
    A: np.ndarray, G: np.ndarray, H: np.ndarray, iterations: int = 100
) -> np.ndarray:
    """The stabilizing solution X of ``X = Aᵀ X (I + G X)⁻¹ A + H`` by structure-preserving
    doubling (Chu, Fan & Lin 2005), symmetrizing G and X at each step.

    The Kalman filter of ``s ← F s`` reading ``c s`` with noise variance r and process
    noise Q has ``A = Fᵀ``, ``G = cᵀ c / r``, ``H = Q`` (X the prior covariance); the
    regulator of ``x ← F x + g u`` with cost ``Σ xᵀ Q x + r u²`` has ``A = F``,
    ``G = g gᵀ / r``, ``H = Q``.

    Parameters
    ----------
    A : ndarray
        Shape ``(m, m)``.
    G, H : ndarray
        Shape ``(m, m)`` each, symmetric, positive semi-definite.
    iterations : int
        Most doubling steps (a count).

    Returns
    -------
    ndarray
        X, shape ``(m, m)``, symmetric.

    Raises
    ------
    ConvergenceError
        When the step's change is still above 1e-13 of X after ``iterations`` steps, or X
        is not finite.

    Examples
    --------
    The scalar regulator of ``x ← x + u`` with cost ``Σ x² + u²``: X = (1 + √5)/2.

    >>> one = np.ones((1, 1))
    >>> round(float(solve_doubling(one, one, one)[0, 0]), 12)
    1.61803398875
    """
    Ak = A.copy()
    X = H.copy()
    eye = np.eye(len(A))
    for _ in range(iterations):
        W = eye + G @ X
        AW = np.linalg.solve(W.T, Ak.T).T  # A_k (I + G X)⁻¹
        G_next = G + AW @ G @ Ak.T
        X_next = X + Ak.T @ X @ np.linalg.solve(W, Ak)
        Ak = AW @ Ak
        G = 0.5 * (G_next + G_next.T)
        done = np.max(np.abs(X_next - X)) <= 1e-13 * max(np.max(np.abs(X_next)), 1e-300)
        X = 0.5 * (X_next + X_next.T)
        if done and np.all(np.isfinite(X)):
            return X
    raise ConvergenceError("the Riccati iteration did not converge")
