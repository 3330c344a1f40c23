"""Least squares from normal equations accumulated one sample at a time.

Memory is constant (a p × p matrix and a p-vector) however long the record, an
estimate exists after every sample, and the final estimate is the batch
least-squares solution of the same rows.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .linalg import solve

#: Below this reciprocal condition number (of the normal matrix scaled to unit
#: diagonal) a fit is called ill-conditioned.
RCOND_MIN = 1e-10
#: Fewest rows of a fit called valid (a count).
MIN_ROWS = 40


class NormalEquations:
    """Accumulated ``XᵀX`` and ``Xᵀy`` of a linear regression ``y ≈ X β``.

    Parameters
    ----------
    p : int
        Number of regressors (a count).
    """

    def __init__(self, p: int) -> None:
        self.p = p
        self.xtx = [[0.0] * p for _ in range(p)]
        self.xty = [0.0] * p
        self.count = 0

    def add(self, x: Sequence[float], y: float, weight: float = 1.0) -> None:
        """Add one row.

        Parameters
        ----------
        x : Sequence[float]
            The regressors, shape ``(p,)``.
        y : float
            The target.
        weight : float
            The row's weight (dimensionless).
        """
        for r, xr in enumerate(x):
            if xr != 0.0:
                wxr = weight * xr
                row = self.xtx[r]
                for c in range(r, self.p):
                    row[c] += wxr * x[c]
                self.xty[r] += wxr * y
        self.count += 1

    def solve(self, columns: Sequence[int] | None = None) -> tuple[list[float], float]:
        """Least-squares coefficients over ``columns``, the others fixed at 0.

        Parameters
        ----------
        columns : Sequence[int], optional
            The regressors fitted (indices); None: all.

        Returns
        -------
        beta : list of float
            Coefficients, shape ``(p,)``: 0 for columns left out, and all 0 when the
            system is singular.
        rcond : float
            The reciprocal condition number of the normal matrix scaled to unit
            diagonal (dimensionless; 0 when singular).
        """
        cols = list(range(self.p)) if columns is None else list(columns)
        beta = [0.0] * self.p
        if self.count == 0:
            return beta, 0.0
        sub, rcond = solve_normal(
            [[self.entry(r, c) for c in cols] for r in cols], [self.xty[r] for r in cols]
        )
        for i, c in enumerate(cols):
            beta[c] = sub[i]
        return beta, rcond

    def entry(self, r: int, c: int) -> float:
        """Element (r, c) of the symmetric ``XᵀX``."""
        return self.xtx[r][c] if r <= c else self.xtx[c][r]


def reciprocal_condition(a: list[list[float]]) -> float:
    """1-norm reciprocal condition number of a small symmetric matrix (exact inverse).

    Parameters
    ----------
    a : list of list of float
        The matrix, shape ``(p, p)``.

    Returns
    -------
    float
        ``1 / (‖a‖₁ ‖a⁻¹‖₁)`` (dimensionless), 0 when ``a`` is singular.
    """
    n = len(a)
    try:
        inv = solve(a, [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)])
    except ValueError:
        return 0.0
    norm = max(math.fsum(abs(a[i][j]) for i in range(n)) for j in range(n))
    norm_inv = max(math.fsum(abs(inv[i][j]) for i in range(n)) for j in range(n))
    if not (math.isfinite(norm_inv) and norm > 0.0 and norm_inv > 0.0):
        return 0.0
    return 1.0 / (norm * norm_inv)


def solve_normal(xtx: list[list[float]], xty: list[float]) -> tuple[list[float], float]:
    """Solve small normal equations, scaled to unit diagonal.

    Parameters
    ----------
    xtx : list of list of float
        ``XᵀX``, shape ``(p, p)``.
    xty : list of float
        ``Xᵀy``, shape ``(p,)``.

    Returns
    -------
    beta : list of float
        The coefficients, shape ``(p,)`` (zeros when singular).
    rcond : float
        The scaled matrix's reciprocal condition number (dimensionless; 0 when
        singular).
    """
    p = len(xty)
    diag = [xtx[i][i] for i in range(p)]
    if min(diag) <= 0.0:
        return [0.0] * p, 0.0
    scale = [1.0 / math.sqrt(x) for x in diag]
    scaled = [[xtx[i][j] * scale[i] * scale[j] for j in range(p)] for i in range(p)]
    rcond = reciprocal_condition(scaled)
    if rcond == 0.0:
        return [0.0] * p, 0.0
    z = solve(scaled, [[xty[i] * scale[i]] for i in range(p)])
    return [z[i][0] * scale[i] for i in range(p)], rcond
