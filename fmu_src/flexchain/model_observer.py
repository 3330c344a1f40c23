"""Model-based state observer of the load chain (``estimator = 1``; beyond the paper).

The chain model of :mod:`arcosim.fmu.flexchain.driven_chain`, driven by the measured motor angle,
predicts every load angle and velocity without lag and without differentiating along
the chain; a steady-state Kalman gain corrects it with the reaction torque observer's
τ̂_reac, which the model predicts through the same ``G(s)``. State
``s = [θ_1…θ_n, ω_1…ω_n, y]`` (y: the model's τ̂_reac), per step of ``h``:

    x_k = Ad x_{k−1} + Bd w_k,         w_k = [θ_m,k−1, v_k],  v_k = (θ_m,k − θ_m,k−1)/h
    y_k = a y_{k−1} + (1 − a) (c x_{k−1} + d w_k),              a = exp(−g_dist h)
    s_k ← s_k + K (τ̂_reac,k − y_k)

Noise model behind K (stated, all parameters of the FMU): the motor angle carries white
noise of ``theta_noise_std`` (rad; an encoder of N counts gives 2π/N/√12), each load
mass an unmodelled white torque of ``torque_noise_std`` (N·m), and τ̂_reac white noise
of ``tau_noise_std`` (N·m). K solves the filter's discrete algebraic Riccati equation
(structure-preserving doubling, standard library only); it and the discrete model are
computed once per distinct step size. Angles are kept relative to the initial motor
angle, so the numbers stay small however far the drive has turned.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from operator import mul

from . import linalg
from .driven_chain import discretize
from .filters import lowpass_pole
from .linalg import Matrix
from .riccati import solve_doubling

#: Discretizations kept for distinct step sizes (a variable-step master may use a few).
CACHE_SIZE = 8
#: Noise levels (N·m) the Kalman design is known to solve: torque_noise_std and
#: tau_noise_std each in this range, neither more than NOISE_RATIO times the other.
#: Checked over n = 1, 3, 8 masses, encoders of 0 (none), 64, 2000 and 2^20 counts, steps
#: 1e-5 … 1e-2 s and g_dist 10 … 1000 rad/s: 3312 designs, none failed
#: (``python -m benchmarks.noise_envelope``); outside it (a noise of 0, or one 1e10 times
#: the other) the Riccati iteration fails to converge or meets a singular matrix. The
#: load-torque state (load_mass > 0) was not part of that check.
NOISE_RANGE = (1e-9, 1e4)
NOISE_RATIO = 1e8  #: the largest ratio of the two noise levels (dimensionless)


@dataclass(frozen=True)
class NoiseModel:
    """Noise levels the Kalman gain is designed for.

    Parameters
    ----------
    theta_noise_std : float
        White noise on the measured motor angle, standard deviation (rad).
    torque_noise_std : float
        Unmodelled white torque on each load mass, standard deviation (N·m).
    tau_noise_std : float
        White noise on τ̂_reac, standard deviation (N·m).

    Examples
    --------
    >>> NoiseModel(theta_noise_std=1e-4, torque_noise_std=1e-3, tau_noise_std=1e-3)
    NoiseModel(theta_noise_std=0.0001, torque_noise_std=0.001, tau_noise_std=0.001)
    """

    theta_noise_std: float
    torque_noise_std: float
    tau_noise_std: float


@dataclass(frozen=True)
class StepModel:
    """Everything one step of a given size needs: ``s ← F s + Γ w``, gain ``K``.

    Parameters
    ----------
    F : Matrix
        State transition, shape ``(m, m)``.
    Gamma : Matrix
        Input matrix for ``w = [θ_m,k−1, v_k]`` (rad, rad/s), shape ``(m, 2)``.
    K : list of float
        Steady-state Kalman gain (per N·m of innovation), shape ``(m,)``.
    """

    F: Matrix
    Gamma: Matrix
    K: list[float]


def filter_riccati(F: Matrix, Q: Matrix, r: float, iterations: int = 100) -> Matrix:
    """Prior covariance P of the steady-state Kalman filter with a scalar measurement
    of the last state: ``P = F (P − P hᵀ h P / (h P hᵀ + r)) Fᵀ + Q``, h = [0 … 0 1].

    Structure-preserving doubling (:func:`~arcosim.fmu.flexchain.riccati.solve_doubling`):
    quadratic convergence, so a few tens of iterations even for modes that ring for minutes.

    Parameters
    ----------
    F : Matrix
        State transition, shape ``(m, m)``.
    Q : Matrix
        Process noise covariance, shape ``(m, m)``, symmetric.
    r : float
        Variance of the measured (last) state, > 0.
    iterations : int
        Most doubling steps (a count).

    Returns
    -------
    Matrix
        P, shape ``(m, m)``, symmetric.

    Raises
    ------
    ValueError
        If the iteration does not converge (or meets a singular matrix).
    """
    m = len(F)
    G = linalg.zeros(m, m)
    G[m - 1][m - 1] = 1.0 / r
    try:
        return solve_doubling(linalg.transpose(F), G, Q, iterations)
    except ValueError:
        raise ValueError("the Kalman gain's Riccati iteration did not converge") from None


def theta_noise_covariance(Gamma: Matrix, theta_noise_std: float, h: float) -> Matrix:
    """Process noise from the motor angle's white noise σ (rad) through the input
    ``w_k = [θ_m,k−1, v_k]``: ``Γ cov(w) Γᵀ`` (v_k differences two noisy samples)."""
    s2 = theta_noise_std**2
    cov_w = [[s2, -s2 / h], [-s2 / h, 2.0 * s2 / (h * h)]]
    return linalg.matmul(linalg.matmul(Gamma, cov_w), linalg.transpose(Gamma))


def measurement_noise(noise: NoiseModel) -> float:
    """Variance of τ̂_reac's white noise (N·m²), floored so the gain stays finite."""
    return max(noise.tau_noise_std**2, 1e-30)


def chain_process_noise(Gamma: Matrix, J: Sequence[float], noise: NoiseModel, h: float) -> Matrix:
    """Process noise of the chain's states over a step of ``h`` s: the motor angle's noise
    through ``Γ`` (:func:`theta_noise_covariance`) plus each load mass's unmodelled torque
    on its velocity (states n … 2n − 1). Shape m × m, m = ``len(Gamma)`` ≥ 2n."""
    n = len(J)
    Q = theta_noise_covariance(Gamma, noise.theta_noise_std, h)
    for i in range(n):
        Q[n + i][n + i] += (noise.torque_noise_std * h / J[i]) ** 2
    return Q


def steady_state_gain(F: Matrix, Q: Matrix, r: float) -> list[float]:
    """Gain ``K`` (length m) of the steady-state Kalman filter of ``s ← F s`` with process
    noise ``Q`` (m × m) and the last state measured with variance ``r``."""
    m = len(F)
    Q = [row[:] for row in Q]
    for i in range(m):  # keeps the Riccati equation regular when every noise is zero
        Q[i][i] += 1e-30
    P = filter_riccati(F, Q, r)
    return [P[i][m - 1] / (P[m - 1][m - 1] + r) for i in range(m)]


def step_model(
    J: Sequence[float],
    k: Sequence[float],
    B: Sequence[float],
    g_dist: float,
    noise: NoiseModel,
    h: float,
    star: bool = False,
) -> StepModel:
    """Discrete model with the DOB's filter, and its steady-state Kalman gain.

    Parameters
    ----------
    J, k, B : Sequence[float]
        Load inertias (kg·m²), stiffnesses (N·m/rad), dampings (N·m·s/rad), shape
        ``(n,)`` each.
    g_dist : float
        DOB bandwidth (rad/s).
    noise : NoiseModel
        The noise levels the gain is designed for.
    h : float
        Step (s).
    star : bool
        The springs as a star from the motor (a link's modes,
        :mod:`arcosim.fmu.flexchain.link_observer`), not a chain.

    Returns
    -------
    StepModel
        ``F``, shape ``(m, m)`` with m = 2n + 1, ``Γ``, shape ``(m, 2)``, and ``K``,
        shape ``(m,)``.

    Raises
    ------
    ValueError
        If the Riccati iteration fails (noise outside :data:`NOISE_RANGE`).

    Examples
    --------
    >>> model = step_model([1e-3], [0.5], [1e-5], 500.0, NoiseModel(1e-4, 1e-3, 1e-3), 1e-3)
    >>> len(model.F), len(model.F[0]), len(model.K)  # m = 2n + 1 = 3
    (3, 3, 3)
    """
    F, Gamma = filtered_chain(J, k, B, g_dist, h, star)
    Q = chain_process_noise(Gamma, J, noise, h)
    return StepModel(F, Gamma, steady_state_gain(F, Q, measurement_noise(noise)))


def filtered_chain(
    J: Sequence[float],
    k: Sequence[float],
    B: Sequence[float],
    g_dist: float,
    h: float,
    star: bool = False,
) -> tuple[Matrix, Matrix]:
    """The discrete chain with the DOB's filter as its last state, ``s ← F s + Γ w``.

    Parameters
    ----------
    J, k, B : Sequence[float]
        Load inertias (kg·m²), stiffnesses (N·m/rad), dampings (N·m·s/rad), shape
        ``(n,)`` each.
    g_dist : float
        DOB bandwidth (rad/s).
    h : float
        Step (s).
    star : bool
        The springs as a star from the motor, not a chain.

    Returns
    -------
    tuple of Matrix
        ``F``, shape ``(m, m)`` with m = 2n + 1, and ``Γ``, shape ``(m, 2)``, for
        ``w = [θ_m,k−1, v_k]`` (rad, rad/s); the last state is the model's τ̂_reac (N·m).

    Examples
    --------
    >>> F, Gamma = filtered_chain((5e-4,), (0.16,), (1e-5,), 100.0, 1e-3)
    >>> len(F), len(Gamma[0])
    (3, 2)
    """
    chain = discretize(J, k, B, h, star=star)
    n = chain.n
    m = 2 * n + 1
    a = lowpass_pole(g_dist, h)
    b = 1.0 - a
    c, d = chain.torque_row()
    F = linalg.zeros(m, m)
    for i in range(2 * n):
        F[i][: 2 * n] = chain.Ad[i][:]
    F[m - 1][: 2 * n] = [b * x for x in c]
    F[m - 1][m - 1] = a
    Gamma = [row[:] for row in chain.Bd] + [[b * d[0], b * d[1]]]
    return F, Gamma


def advance(
    F: Matrix, Gamma: Matrix, s: Sequence[float], u_prev: float, u: float, h: float
) -> list[float]:
    """One step of a step model, ``F s + Γ [u_prev, (u − u_prev) / h]``, the motor's
    angle linear over the step (``math.fsum``: the same sums on every CPython).

    Parameters
    ----------
    F, Gamma : Matrix
        The step model, shapes ``(m, m)`` and ``(m, 2)``.
    s : Sequence[float]
        The state at the previous sample, shape ``(m,)``.
    u_prev, u : float
        The motor angle relative to the start at the previous sample and at this one
        (rad).
    h : float
        Time between them (s), > 0.

    Returns
    -------
    list of float
        The state at this sample, shape ``(m,)``.

    Examples
    --------
    >>> advance([[1.0, 0.0], [0.0, 0.5]], [[0.0, 0.0], [1.0, 0.0]], [2.0, 2.0], 1.0, 3.0, 0.5)
    [2.0, 2.0]
    """
    w0, w1 = u_prev, (u - u_prev) / h
    return [math.fsum(map(mul, row, s)) + g[0] * w0 + g[1] * w1 for row, g in zip(F, Gamma)]


class ModelObserver:
    """Angles and velocities of the n load masses from θ_m and τ̂_reac.

    Parameters
    ----------
    J, k, B : Sequence[float]
        Per mass / spring inertia (kg·m²), stiffness (N·m/rad, > 0), damping
        (N·m·s/rad, ≥ 0), shape ``(n,)`` each.
    g_dist : float
        DOB bandwidth (rad/s), the ``G(s)`` of τ̂_reac.
    noise : NoiseModel
        Noise levels for the Kalman gain.
    theta0 : float
        Motor angle at start (rad); the chain starts at rest, aligned.

    Attributes
    ----------
    theta : list of float
        After :meth:`step`: estimated angles θ̂_1 … θ̂_n (rad) at the last sample,
        shape ``(n,)``.
    omega : list of float
        Estimated velocities (rad/s) at the last sample, shape ``(n,)``.
    innovation : float
        τ̂_reac minus the model's prediction at the last sample (N·m).
    """

    _transient = ("_models",)  # derived from the settings; rebuilt after an FMU state restore

    def __init__(
        self,
        J: Sequence[float],
        k: Sequence[float],
        B: Sequence[float],
        g_dist: float,
        noise: NoiseModel,
        theta0: float,
    ) -> None:
        self.J, self.k, self.B = tuple(J), tuple(k), tuple(B)
        self.g_dist = g_dist
        self.noise = noise
        self.n = n = len(J)
        self.theta0 = theta0
        self.u_prev = 0.0  # motor angle at the previous sample, relative to theta0
        self.s = [0.0] * (2 * n + 1)
        self.theta = [theta0] * n
        self.omega = [0.0] * n
        self.innovation = 0.0
        self._models: dict[float, StepModel] = {}

    def model(self, h: float) -> StepModel:
        """The step model for ``h`` (computed on first use, then cached)."""
        found = self._models.get(h)
        if found is None:
            if len(self._models) >= CACHE_SIZE:
                self._models.pop(next(iter(self._models)))
            found = self.design(h)
            self._models[h] = found
        return found

    def design(self, h: float) -> StepModel:
        """The step model for ``h`` (:func:`step_model`; subclasses add states)."""
        return step_model(self.J, self.k, self.B, self.g_dist, self.noise, h)

    def predict(self, h: float, theta_m: float, s: Sequence[float]) -> list[float]:
        """The step model's state at this sample from the state ``s`` at the previous
        one, without the Kalman correction.

        The motor's angle enters as the model's input over the step: from this
        estimator's previous sample (``u_prev``) to ``theta_m``.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        theta_m : float
            The measured motor angle at this sample (rad).
        s : Sequence[float]
            A state at the previous sample, as :attr:`s` (its shape).

        Returns
        -------
        list of float
            The predicted state, its last entry the predicted τ̂_reac (N·m).

        Examples
        --------
        >>> noise = NoiseModel(theta_noise_std=1e-3, torque_noise_std=1e-3, tau_noise_std=1e-3)
        >>> est = ModelObserver((5e-4,), (0.16,), (1e-5,), 500.0, noise, 0.0)
        >>> est.predict(1e-3, 0.0, est.s)  # at rest, nothing moves
        [0.0, 0.0, 0.0]
        """
        sm = self._models.get(h) or self.model(h)
        return advance(sm.F, sm.Gamma, s, self.u_prev, theta_m - self.theta0, h)

    def step(self, h: float, tau_reac_hat: float, theta_m: float) -> None:
        """Take the sample that ends a step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        tau_reac_hat : float
            The reaction torque observer's estimate τ̂_reac (N·m).
        theta_m : float
            The measured motor angle (rad).
        """
        sm = self._models.get(h) or self.model(h)
        pred = self.predict(h, theta_m, self.s)
        e = tau_reac_hat - pred[-1]
        self.s = s = [p + kk * e for p, kk in zip(pred, sm.K)]
        self.innovation = e
        self.u_prev = theta_m - self.theta0
        n = self.n
        t0 = self.theta0
        self.theta = [t0 + x for x in s[:n]]
        self.omega = s[n : 2 * n]
