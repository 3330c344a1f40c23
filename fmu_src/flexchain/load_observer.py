"""Sensorless load torque: the model-based observer with the external torque on one load
mass as a state (``load_mass``; beyond the paper).

The chain model of :mod:`arcosim.fmu.flexchain.model_observer`, driven by the measured motor angle
(linear between samples), augmented with the unknown torque ``d`` on load mass L
(sign of the plant's ``tau_ext[L]``: positive accelerates mass L), held over each
step. State ``s = [θ_1…θ_n, ω_1…ω_n, d, y]`` (y: the model's τ̂_reac), per step of h:

    d_k = d_{k−1} + w_k                           (random walk, the torque over step k)
    x_k = Ad x_{k−1} + Bd [θ_m,k−1, v_k] + b_d d_k
    τ̄_k = Σ_i J_i (ω_i,k − ω_i,k−1) / h − d_k     (eq. 6: τ_reac = Σ J_i θ̈_i − Σ τ_ext)
    y_k = a y_{k−1} + (1 − a) τ̄_k,                 a = exp(−g_dist h)
    s_k ← s_k + K (τ̂_reac,k − y_k)

(``Ad``, ``Bd``, ``b_d``: one matrix exponential of the chain augmented with θ_m, v and
d, all exact for a motor angle linear and a torque constant over the step.)

Noise model behind K: that of :mod:`arcosim.fmu.flexchain.model_observer`, plus the random walk's
increments, white with standard deviation ``ω_L σ_τ h`` per step (ω_L the
``bandwidth``, σ_τ the noise on τ̂_reac): a torque seen directly through that noise
would then be estimated with a first-order bandwidth of ω_L, since the steady-state
Kalman gain of a random walk is √(q_c / r_c) = ω_L with q_c = (ω_L σ_τ)² h and
r_c = σ_τ² h. A torque on a load mass reaches τ_reac with a static gain of −1 (the
springs from the motor to mass L carry it), so ω_L sets the estimate's bandwidth; the
chain adds its own lag, about a quarter period of its first clamped mode, since above
that mode a torque on mass L reaches the motor attenuated as ω^(−2L) (measured: README).
The gain is designed jointly with the chain's states (one Riccati equation).

The output ``tau_load`` is the Kalman estimate of d through a second-order Butterworth
low-pass at ``SMOOTHING_RATIO · ω_L`` (exact for the step taken). A Kalman filter
passes white measurement noise to its estimates with a first-order roll-off (d̂ is the
sum of its corrections), and the reaction torque observer's largest error is far above
ω_L: with the encoder's backward-difference velocity the DOB pairs the current with the
acceleration half a step late (docs/method.md), an error of J_m Δα/2 per step that
rings at the drive's resonances (on the bench, 0.015 N·m at its 90 rad/s mode under a
2 A multi-sine: an rms error of 9 % of a 5 mN·m load step through the first-order
roll-off, 0.2 % after the low-pass). The chain model uses the unsmoothed d.

A random walk and not a first-order Gauss–Markov model: the filter then has integral
action, so a constant torque is estimated without bias (a Gauss–Markov torque decays
to zero in the model, and the estimate of a constant torque settles short of it).

Observability (what the motor side shows, with θ_m an input and τ̂_reac the output):

* one torque on any load mass: observable. The clamped chain (motor angle given) is
  observable from the torque of spring 1 (its stiffness matrix is a Jacobi matrix:
  every mode moves mass 1), and a constant d adds a mode at s = 0 whose static gain to
  τ_reac is −1 ≠ 0 (Popov–Belevitch–Hautus test at s = 0).
* constant torques on several masses: only their sum. Every load mass has the same
  static gain −1, so +d on mass a and −d on mass b twist the springs between them and
  leave τ_reac unchanged once the chain has settled: two random-walk torques are
  unobservable (PBH at s = 0 fails). Hence one mass at a time; an estimator set to mass
  L that meets a constant torque on another mass j converges to it all the same (the
  sum), but its static deflections of the springs between j and L are wrong, and its
  transient follows mass L's dynamics, not mass j's.
* a torque on the motor itself (an error in the actuator terms: friction, k_t) enters
  τ̂_reac directly, and at low frequency looks exactly like a load torque: the estimate
  is as good as the actuator terms removed by the reaction torque observer.
* the springs do not enter the static balance, so a constant torque's settled estimate
  does not depend on the k_i (stiffness errors act only through the flexible motion's
  prediction error); the J_i do, through the momentum Σ J_i θ̈_i of a moving chain.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from . import defaults, linalg
from .driven_chain import continuous_matrices, discretize
from .filters import lowpass_pole
from .linalg import Matrix
from .model_observer import (
    ModelObserver,
    NoiseModel,
    StepModel,
    chain_process_noise,
    measurement_noise,
    steady_state_gain,
)

#: The output's low-pass sits at this multiple of ω_L (see the module doc).
SMOOTHING_RATIO = 2.0


def load_column(
    J: Sequence[float], k: Sequence[float], B: Sequence[float], h: float, load_mass: int
) -> list[float]:
    """``b_d``: the change of the load state ``x = [θ_1…θ_n, ω_1…ω_n]`` over a step
    caused by a unit torque on one load mass, held over the step, starting from rest.

    ``∫_0^h e^{A s} ds · e_L / J_L``, from the matrix exponential of ``[[A h, e_L h / J_L],
    [0, 0]]``.

    Parameters
    ----------
    J, k, B : Sequence[float]
        Load inertias (kg·m²), spring stiffnesses (N·m/rad) and dampings (N·m·s/rad),
        shape ``(n,)`` each.
    h : float
        Step (s).
    load_mass : int
        The mass the torque acts on, 1 … n (an index).

    Returns
    -------
    list of float
        ``b_d``, shape ``(2n,)``: angles (rad per N·m) then velocities (rad/s per N·m).
    """
    A, _ = continuous_matrices(J, k, B)
    m = len(A)
    n = m // 2
    Ah = [[h * a for a in row] for row in A]
    Eh = [[0.0] for _ in range(m)]
    Eh[n + load_mass - 1][0] = h / J[load_mass - 1]  # h / J_L as it was: not h · (1 / J_L)
    _, G = linalg.hold(Ah, Eh, 1.0)
    return [row[0] for row in G]


@dataclass(frozen=True)
class LoadStepModel(StepModel):
    """:class:`~arcosim.fmu.flexchain.model_observer.StepModel` plus the output low-pass over the
    step: ``z ← Φ z + φ d̂`` (z = [value, rate]), the output is ``z[0]``."""

    Phi: Matrix
    phi: list[float]


def smoothing_filter(bandwidth: float, h: float) -> tuple[Matrix, list[float]]:
    """Second-order Butterworth low-pass over one step, its input held over the step.

    Parameters
    ----------
    bandwidth : float
        Corner frequency (rad/s).
    h : float
        Step (s).

    Returns
    -------
    tuple of (list of list of float, list of float)
        ``Φ``, shape ``(2, 2)``, and ``φ``, shape ``(2,)``: ``z ← Φ z + φ u`` for the
        state z = [value, rate] and the input u held over the step.
    """
    w = bandwidth
    Ah = [[0.0, h], [-w * w * h, -math.sqrt(2.0) * w * h]]  # the step in, as it was
    Phi, G = linalg.hold(Ah, [[0.0], [w * w * h]], 1.0)
    return Phi, [row[0] for row in G]


def smooth(Phi: Matrix, phi: Sequence[float], z: Sequence[float], u: float) -> list[float]:
    """One step of :func:`smoothing_filter`'s low-pass: ``Φ z + φ u``.

    Parameters
    ----------
    Phi, phi : Matrix, Sequence[float]
        From :func:`smoothing_filter`, shapes ``(2, 2)`` and ``(2,)``.
    z : Sequence[float]
        The state [value, rate] at the previous sample, shape ``(2,)``.
    u : float
        The input held over the step.

    Returns
    -------
    list of float
        The state at this sample, shape ``(2,)``; its first entry the output.

    Examples
    --------
    >>> smooth([[1.0, 0.0], [0.0, 1.0]], [0.5, 0.25], [0.0, 0.0], 2.0)
    [1.0, 0.5]
    """
    (p00, p01), (p10, p11) = Phi
    z0, z1 = z
    return [p00 * z0 + p01 * z1 + phi[0] * u, p10 * z0 + p11 * z1 + phi[1] * u]


def check_load_settings(n: int, load_mass: int, bandwidth: float) -> None:
    """Refuse a ``load_mass`` outside 1 … n or a bandwidth ω_L that is not > 0.

    Parameters
    ----------
    n : int
        Number of load masses (a count).
    load_mass : int
        The mass the torque acts on (an index).
    bandwidth : float
        ω_L (rad/s).

    Raises
    ------
    ValueError
        Naming the setting.
    """
    if not 1 <= load_mass <= n:
        raise ValueError(f"load_mass = {load_mass}: use a load mass 1 … {n}")
    if not bandwidth > 0.0:
        raise ValueError(f"load torque bandwidth {bandwidth!r} rad/s: it must be > 0")


def load_prediction(
    J: Sequence[float],
    k: Sequence[float],
    B: Sequence[float],
    g_dist: float,
    h: float,
    load_mass: int,
) -> tuple[Matrix, Matrix]:
    """The step model with the load torque and the DOB's filter, without a Kalman gain.

    Parameters
    ----------
    J, k, B : Sequence[float]
        Load inertias (kg·m²), stiffnesses (N·m/rad), dampings (N·m·s/rad), shape
        ``(n,)`` each.
    g_dist : float
        DOB bandwidth (rad/s).
    h : float
        Step (s).
    load_mass : int
        The mass the torque acts on, 1 … n (an index).

    Returns
    -------
    tuple of (list of list of float, list of list of float)
        ``F``, shape ``(m, m)`` with m = 2n + 2, and ``Γ``, shape ``(m, 2)``: the state
        ``[θ_1…θ_n, ω_1…ω_n, d, y]`` steps as ``F s + Γ [u_prev, (u − u_prev) / h]``
        (module doc).

    Examples
    --------
    >>> F, Gamma = load_prediction((5e-4,), (0.16,), (1e-5,), 100.0, 1e-3, 1)
    >>> len(F), len(Gamma[0]), F[2][2]  # d is a random walk: held over the step
    (4, 2, 1.0)
    """
    n = len(J)
    chain = discretize(J, k, B, h)
    b_d = load_column(J, k, B, h, load_mass)
    m = 2 * n + 2
    a = lowpass_pole(g_dist, h)
    b = 1.0 - a
    c, du = chain.torque_row()
    e_d = math.fsum(J[i] / h * b_d[n + i] for i in range(n)) - 1.0  # τ̄ per unit d over the step
    F = linalg.zeros(m, m)
    for i in range(2 * n):
        F[i][: 2 * n] = chain.Ad[i][:]
        F[i][2 * n] = b_d[i]
    F[2 * n][2 * n] = 1.0
    F[m - 1][: 2 * n] = [b * x for x in c]
    F[m - 1][2 * n] = b * e_d
    F[m - 1][m - 1] = a
    Gamma = [row[:] for row in chain.Bd] + [[0.0, 0.0], [b * du[0], b * du[1]]]
    return F, Gamma


def load_step_model(
    J: Sequence[float],
    k: Sequence[float],
    B: Sequence[float],
    g_dist: float,
    noise: NoiseModel,
    h: float,
    load_mass: int,
    bandwidth: float,
) -> StepModel:
    """Discrete model with the load torque and the DOB's filter, and its Kalman gain.

    Parameters
    ----------
    J, k, B : Sequence[float]
        Load inertias (kg·m²), stiffnesses (N·m/rad), dampings (N·m·s/rad), shape
        ``(n,)`` each.
    g_dist : float
        DOB bandwidth (rad/s).
    noise : NoiseModel
        The chain's noise model (:class:`~arcosim.fmu.flexchain.model_observer.NoiseModel`).
    h : float
        Step (s).
    load_mass : int
        The mass the torque acts on, 1 … n (an index).
    bandwidth : float
        ω_L (rad/s), > 0: sets the random walk's increments (module doc).

    Returns
    -------
    LoadStepModel
        ``F``, shape ``(m, m)`` with m = 2n + 2, ``Γ``, shape ``(m, 2)``, the gain ``K``,
        shape ``(m,)``, and the output low-pass at ``SMOOTHING_RATIO · bandwidth``.

    Raises
    ------
    ValueError
        For a ``load_mass`` outside 1 … n or a bandwidth ≤ 0.
    """
    n = len(J)
    check_load_settings(n, load_mass, bandwidth)
    F, Gamma = load_prediction(J, k, B, g_dist, h, load_mass)
    m = 2 * n + 2
    Q = chain_process_noise(Gamma, J, noise, h)
    r = measurement_noise(noise)
    q = (bandwidth * math.sqrt(r) * h) ** 2  # the random walk's increment variance
    g = [F[i][2 * n] for i in range(m)]  # where an increment of d goes within the step
    for i in range(m):
        for j in range(m):
            Q[i][j] += q * g[i] * g[j]
    Phi, phi = smoothing_filter(SMOOTHING_RATIO * bandwidth, h)
    return LoadStepModel(F, Gamma, steady_state_gain(F, Q, r), Phi, phi)


class LoadTorqueObserver(ModelObserver):
    """Load angles and velocities, and the external torque on one load mass.

    Parameters
    ----------
    J, k, B, g_dist, noise, theta0
        As :class:`~arcosim.fmu.flexchain.model_observer.ModelObserver`.
    load_mass : int
        The mass the torque acts on, 1 … n (an index).
    bandwidth : float
        ω_L (rad/s), > 0 (module doc).

    Attributes
    ----------
    tau_load : float
        After :meth:`step`, besides ModelObserver's: the estimated torque on
        ``load_mass`` (N·m; positive accelerates the mass, as the plant's ``tau_ext``),
        the Kalman estimate of the torque over the last step, smoothed (module doc).
    smoothing : list of float
        The low-pass's state [value (N·m), rate (N·m/s)], shape ``(2,)``.

    Raises
    ------
    ValueError
        For a ``load_mass`` outside 1 … n or a bandwidth ≤ 0.
    """

    def __init__(
        self,
        J: Sequence[float],
        k: Sequence[float],
        B: Sequence[float],
        g_dist: float,
        noise: NoiseModel,
        theta0: float,
        load_mass: int,
        bandwidth: float = defaults.LOAD_TORQUE_BANDWIDTH,
    ) -> None:
        n = len(J)
        check_load_settings(n, load_mass, bandwidth)
        super().__init__(J, k, B, g_dist, noise, theta0)
        self.load_mass = load_mass
        self.bandwidth = bandwidth
        self.s = [0.0] * (2 * n + 2)
        self.tau_load = 0.0
        self.smoothing = [0.0, 0.0]

    def design(self, h: float) -> LoadStepModel:
        """The step model for a step of ``h`` (s): :func:`load_step_model`."""
        return load_step_model(
            self.J, self.k, self.B, self.g_dist, self.noise, h, self.load_mass, self.bandwidth
        )

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
        super().step(h, tau_reac_hat, theta_m)
        sm = self._models[h]
        self.smoothing = smooth(sm.Phi, sm.phi, self.smoothing, self.s[2 * self.n])
        self.tau_load = self.smoothing[0]
