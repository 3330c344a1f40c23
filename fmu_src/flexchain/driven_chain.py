"""The load chain driven by the motor angle: the one chain model the model-based
observer (:mod:`arcosim.fmu.flexchain.model_observer`) and the offline output-error
identification (:mod:`arcosim.identification.fit.output_error`) share.

The motor angle is taken as linear between two samples, so over the step that ends at
``t_k`` it moves with the constant speed ``v_k = (θ_m,k − θ_m,k−1) / h``. The load state
``x = [θ_1 … θ_n, ω_1 … ω_n]`` then follows, exactly,

    x_k = Ad x_{k−1} + Bd [θ_m,k−1, v_k]

(matrix exponential of the system augmented with θ_m and v). The reaction torque on the
motor averaged over the step is the load's momentum change over it (no external torque
on the loads in the model):

    τ̄_k = Σ_i J_i (ω_i,k − ω_i,k−1) / h,

which is what the DOB's paired step torque measures (docs/method.md), before its
low-pass ``G(s)``.

Standard library only; ``expm`` may be swapped for a faster one (scipy offline).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from . import linalg
from .chain import star_matrix
from .linalg import Matrix


def continuous_matrices(
    J: Sequence[float], k: Sequence[float], B: Sequence[float], star: bool = False
) -> tuple[Matrix, Matrix]:
    """``ẋ = A x + E [θ_m, θ̇_m]`` for the load state ``x = [θ_1…θ_n, ω_1…ω_n]``.

    Parameters
    ----------
    J : Sequence[float]
        Load inertias (kg·m²), shape ``(n,)``.
    k, B : Sequence[float]
        Stiffness (N·m/rad) and damping (N·m·s/rad) of springs 1 … n, shape ``(n,)``
        each.
    star : bool
        False: a chain (spring i joins body i − 1 and body i); True: a star (spring i
        joins the motor and body i, :func:`~arcosim.fmu.flexchain.chain.star_matrix`:
        a link's modes).

    Returns
    -------
    tuple of Matrix
        ``A``, shape ``(2n, 2n)``, and ``E``, shape ``(2n, 2)`` (SI units: 1/s, 1/s²).
    """
    if star:
        return _star_matrices(J, k, B)
    n = len(J)
    A = linalg.zeros(2 * n, 2 * n)
    E = linalg.zeros(2 * n, 2)
    for i in range(n):
        A[i][n + i] = 1.0
    for i in range(n):
        row = A[n + i]
        # spring i+1 (between body i and load i+1; body 0 is the motor)
        row[i] -= k[i] / J[i]
        row[n + i] -= B[i] / J[i]
        if i > 0:
            row[i - 1] += k[i] / J[i]
            row[n + i - 1] += B[i] / J[i]
        else:
            E[n][0] = k[0] / J[0]
            E[n][1] = B[0] / J[0]
        if i + 1 < n:  # spring i+2 pulls back
            row[i] -= k[i + 1] / J[i]
            row[n + i] -= B[i + 1] / J[i]
            row[i + 1] += k[i + 1] / J[i]
            row[n + i + 1] += B[i + 1] / J[i]
    return A, E


def _star_matrices(
    J: Sequence[float], k: Sequence[float], B: Sequence[float]
) -> tuple[Matrix, Matrix]:
    """:func:`continuous_matrices` of a star, from its Laplacians (body 0 the motor)."""
    n = len(J)
    K, C = star_matrix(k), star_matrix(B)
    A = linalg.zeros(2 * n, 2 * n)
    E = linalg.zeros(2 * n, 2)
    for i in range(n):
        A[i][n + i] = 1.0
        row = A[n + i]
        for j in range(n):
            row[j] = -K[i + 1][j + 1] / J[i]
            row[n + j] = -C[i + 1][j + 1] / J[i]
        E[n + i] = [-K[i + 1][0] / J[i], -C[i + 1][0] / J[i]]
    return A, E


@dataclass(frozen=True)
class DiscreteChain:
    """The chain over one step of ``h`` s (see the module docstring).

    Parameters
    ----------
    h : float
        Step (s).
    J : tuple of float
        Load inertias (kg·m²), shape ``(n,)``.
    Ad : Matrix
        State transition, shape ``(2n, 2n)``.
    Bd : Matrix
        Input matrix for ``[θ_m,k−1, v_k]`` (rad, rad/s), shape ``(2n, 2)``.
    """

    h: float
    J: tuple[float, ...]
    Ad: Matrix
    Bd: Matrix

    @property
    def n(self) -> int:
        """Number of load masses."""
        return len(self.J)

    def torque_row(self) -> tuple[list[float], list[float]]:
        """The step's mean reaction torque ``τ̄_k = c · x_{k−1} + d · [θ_m,k−1, v_k]`` (N·m).

        Returns
        -------
        tuple of (list of float, list of float)
            The rows ``c``, shape ``(2n,)``, and ``d``, shape ``(2,)``.
        """
        n, h = self.n, self.h
        c = [0.0] * (2 * n)
        d = [0.0, 0.0]
        for i in range(n):
            w = self.J[i] / h
            for j in range(2 * n):
                c[j] += w * (self.Ad[n + i][j] - (1.0 if j == n + i else 0.0))
            d[0] += w * self.Bd[n + i][0]
            d[1] += w * self.Bd[n + i][1]
        return c, d


def discretize(
    J: Sequence[float],
    k: Sequence[float],
    B: Sequence[float],
    h: float,
    expm: Callable[[Matrix], Matrix] = linalg.expm,
    star: bool = False,
) -> DiscreteChain:
    """Exact discrete chain for a motor angle linear over each step of ``h`` s.

    The augmented state ``[x, θ_m, v]`` has ``d/dt θ_m = v``, ``d/dt v = 0``; one
    matrix exponential of size 2n + 2 gives ``Ad`` and ``Bd``.

    Parameters
    ----------
    J, k, B : Sequence[float]
        Load inertias (kg·m²), stiffnesses (N·m/rad), dampings (N·m·s/rad), shape
        ``(n,)`` each.
    h : float
        Step (s).
    expm : callable
        The matrix exponential (:func:`~arcosim.fmu.flexchain.linalg.expm`, or scipy's
        offline).
    star : bool
        The springs as a star from the motor, not a chain (:func:`continuous_matrices`).

    Returns
    -------
    DiscreteChain
        ``Ad`` and ``Bd`` for this step.
    """
    A, E = continuous_matrices(J, k, B, star)
    m = len(A)
    F = linalg.zeros(m + 2, m + 2)
    for r in range(m):
        F[r][:m] = [h * a for a in A[r]]
        F[r][m] = h * E[r][0]
        F[r][m + 1] = h * E[r][1]
    F[m][m + 1] = h  # θ_m grows by v·h over the step
    X = expm(F)
    Ad = [row[:m] for row in X[:m]]
    Bd = [[row[m], row[m + 1]] for row in X[:m]]
    return DiscreteChain(h, tuple(J), Ad, Bd)
