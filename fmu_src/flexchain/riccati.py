"""The discrete algebraic Riccati equation by structure-preserving doubling: the one
solver behind the observers' Kalman gains and the controller's state feedback.

Both are ``X = Aᵀ X (I + G X)⁻¹ A + H`` for some ``A``, ``G = G ᵀ ≥ 0``, ``H = Hᵀ ≥ 0``:

* the Kalman filter of ``s ← F s`` with the measurement ``c s`` (variance r) and process
  noise Q: ``A = Fᵀ``, ``G = cᵀ c / r``, ``H = Q``, and X is the prior covariance;
* the linear-quadratic regulator of ``x ← F x + g u`` with cost ``Σ xᵀ Q x + r u²``:
  ``A = F``, ``G = g gᵀ / r``, ``H = Q``, and X is the cost-to-go.

Structure-preserving doubling (Chu, Fan & Lin 2005) converges quadratically, so a few
tens of iterations suffice even for modes that ring for minutes. Standard library only.
"""

from __future__ import annotations

from . import linalg
from .linalg import Matrix


def solve_doubling(A: Matrix, G: Matrix, H: Matrix, iterations: int = 100) -> Matrix:
    """The stabilizing solution X of ``X = Aᵀ X (I + G X)⁻¹ A + H``.

    Parameters
    ----------
    A : Matrix
        Shape ``(m, m)``.
    G, H : Matrix
        Shape ``(m, m)`` each, symmetric, positive semi-definite.
    iterations : int
        Most doubling steps (a count).

    Returns
    -------
    Matrix
        X, shape ``(m, m)``, symmetric.

    Raises
    ------
    ValueError
        If the iteration does not converge (or meets a singular matrix).

    Examples
    --------
    The scalar regulator of ``x ← x + u`` with cost ``Σ x² + u²``: X = (1 + √5)/2.

    >>> round(solve_doubling([[1.0]], [[1.0]], [[1.0]])[0][0], 12)
    1.618033988750
    """
    m = len(A)
    G = [row[:] for row in G]
    H = [row[:] for row in H]
    eye = linalg.identity(m)
    for _ in range(iterations):
        W = linalg.add(eye, linalg.matmul(G, H))
        both = linalg.solve(W, [ra + rg for ra, rg in zip(A, G)])
        WA = [row[:m] for row in both]
        WG = [row[m:] for row in both]
        At = linalg.transpose(A)
        H_next = linalg.add(H, linalg.matmul(At, linalg.matmul(H, WA)))
        G = linalg.add(G, linalg.matmul(linalg.matmul(A, WG), At))
        A = linalg.matmul(A, WA)
        change = linalg.norm_inf(linalg.add(H_next, H, -1.0))
        H = H_next
        if change <= 1e-13 * max(linalg.norm_inf(H), 1e-300):
            return [[0.5 * (H[i][j] + H[j][i]) for j in range(m)] for i in range(m)]
    raise ValueError("the Riccati iteration did not converge")
