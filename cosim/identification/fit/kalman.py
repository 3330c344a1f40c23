"""The drive as one linear model, and its steady-state Kalman predictor and smoother.

Motor and load chain (state ``[θ_m, θ_1…θ_n, ω_m, ω_1…ω_n]``, then a slow load's random
walk) driven by the motor torque and a load torque on the last mass, both held over a
step (:func:`discrete_drive`); the encoder reads the motor angle with a uniform error
of one count (variance q²/12), and an unmodelled torque on the motor is the process
noise. :class:`Kalman` gives the one-step predictions of the encoder angle (whose
errors, :func:`innovations`, the prediction-error fit minimizes) and the
Rauch–Tung–Striebel smoothed states (whose motor velocity sets the friction's sign in
the fit's second pass).
"""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass

import numpy as np
import scipy.linalg

from arcosim.fmu.flexchain.chain import spring_matrix, star_matrix
from arcosim.identification.fit.linear_model import ConvergenceError, hold, solve_doubling
from arcosim.identification.fit.modal_recursion import linear_recursion, output_recursion
from arcosim.identification.records.record import EncoderRecord


@dataclass(frozen=True)
class Drive:
    """One drive model: chain, motor friction, load torque.

    Attributes
    ----------
    J : ndarray
        Load inertias (kg·m²), shape ``(n,)``.
    k : ndarray
        Spring stiffnesses (N·m/rad), shape ``(n,)``, k_1 from the motor to J_1.
    B : ndarray
        Spring dampings (N·m·s/rad), shape ``(n,)``.
    D_m : float
        Motor viscous friction (N·m·s/rad).
    f_c : float
        Motor Coulomb friction (N·m).
    tau_load : float
        Constant load torque on the last mass (N·m).
    star : bool
        The masses each hang on their own spring and damper from the motor (a flexible
        link's modes, :meth:`arcosim.identification.link.beam_model.ModalModel.star`)
        instead of the chain's k_1 from the motor to J_1, k_2 from J_1 to J_2, ….
    J_rigid : float
        Inertia rigid on the motor besides the record's J_m (kg·m²): the load of a rigid
        drive (n = 0, ``J_total − J_m``), a link's part rigid on the hub; 0 for a chain.
    """

    J: np.ndarray
    k: np.ndarray
    B: np.ndarray
    D_m: float
    f_c: float
    tau_load: float = 0.0
    _: KW_ONLY  # the two below by name only: a positional slip would swap them
    star: bool = False
    J_rigid: float = 0.0

    def coupling(self, values: np.ndarray) -> np.ndarray:
        """Stiffness (``values`` = k) or damping (``values`` = B) matrix on the angles
        ``[θ_m, θ_1…θ_n]``, shape ``(n + 1, n + 1)``: the chain's or the star's."""
        values = np.asarray(values, dtype=float)
        laplacian = star_matrix if self.star else spring_matrix
        return np.array(laplacian([float(x) for x in values]))


@dataclass(frozen=True)
class Kalman:
    """Steady-state Kalman filter of motor + chain (state ``[θ_m, θ_1…θ_n, ω_m, …]``,
    then the load's random walk when ``load="slow"``; S states).

    Attributes
    ----------
    A : ndarray
        State matrix over one step (dimensionless), shape ``(S, S)``.
    Bd : ndarray
        Input matrix over one step, shape ``(S, 2)``; columns: the motor torque, the
        load torque on the last mass (state units per N·m).
    prior : ndarray
        P⁻, the prior covariance (state units squared: rad², …), shape ``(S, S)``.
    variance : float
        Of the innovation (rad²).
    gain : ndarray
        Filter gain P⁻Hᵀ/S (state units per rad), shape ``(S,)``.
    """

    A: np.ndarray
    Bd: np.ndarray  # columns: motor torque, load torque on the last mass
    prior: np.ndarray  # P⁻ (rad², …)
    variance: float  # of the innovation (rad²)
    gain: np.ndarray  # filter gain P⁻Hᵀ/S

    @classmethod
    def of(cls, record: EncoderRecord, drive: Drive) -> Kalman:
        """The filter of ``drive`` with ``record``'s step, encoder count and noises."""
        A, Bd = discrete_drive(record, drive)
        size = len(A)
        H = np.zeros((1, size))
        H[0, 0] = 1.0
        Q = np.outer(Bd[:, 0], Bd[:, 0]) * record.torque_std**2
        if record.load == "slow":
            Q[-1, -1] += record.load_std**2
        R = record.count**2 / 12.0
        P = filter_riccati(A, Q, R)
        S = float(P[0, 0] + R)
        return cls(A, Bd, P, S, P[:, 0] / S)

    def _inputs(self, record: EncoderRecord, drive: Drive) -> tuple[np.ndarray, np.ndarray]:
        """Predictor inputs ``[y_k − y_0, torque_{k+1}, 1]`` (shape (3, N − 1)) and their
        matrix (S, 3): x⁻_{k+1} = F x⁻_k + G u_k, angles relative to the first reading."""
        y = record.theta_m - record.theta_m[0]
        torque = record.drive - drive.f_c * record.sign
        inputs = np.vstack([y[:-1], torque[1:], np.ones(len(y) - 1)])
        G = np.column_stack([self.A @ self.gain, self.Bd[:, 0], self.Bd[:, 1] * drive.tau_load])
        return inputs, G

    def _F(self) -> np.ndarray:
        F = self.A.copy()
        F[:, 0] -= self.A @ self.gain
        return F

    def predicted_angle(self, record: EncoderRecord, drive: Drive) -> np.ndarray:
        """H x⁻_k for k = 0 … N − 1 (relative to the first reading), shape (N,)."""
        inputs, G = self._inputs(record, drive)
        return output_recursion(self._F(), G, inputs)

    def predicted(self, record: EncoderRecord, drive: Drive) -> np.ndarray:
        """x⁻_0 … x⁻_{N−1} (angles relative to the first reading), shape (N, S)."""
        inputs, G = self._inputs(record, drive)
        return linear_recursion(self._F(), G, inputs, np.zeros(len(G))).T

    def smoothed(self, record: EncoderRecord, drive: Drive) -> np.ndarray:
        """Rauch–Tung–Striebel smoothed states x_0 … x_{N−1} (angles absolute), (N, S)."""
        before = self.predicted(record, drive)
        y = record.theta_m - record.theta_m[0]
        after = before + np.outer(y - before[:, 0], self.gain)  # filtered
        posterior = self.prior - np.outer(self.gain, self.prior[0])
        G = posterior @ self.A.T @ np.linalg.inv(self.prior)
        inputs = np.hstack([after[:-1], before[1:]])[::-1].T
        both = np.hstack([np.eye(len(G)), -G])
        states = linear_recursion(G, both, inputs, after[-1]).T[::-1]
        m = (len(self.A) - (record.load == "slow")) // 2
        states[:, :m] += record.theta_m[0]
        return states


def filter_riccati(A: np.ndarray, Q: np.ndarray, R: float, iterations: int = 80) -> np.ndarray:
    """Prior covariance P of the steady-state Kalman filter that reads the first state
    with noise variance R: ``P = A P Aᵀ − A P h (hᵀ P h + R)⁻¹ hᵀ P Aᵀ + Q`` (h = e_1).

    Structure-preserving doubling (:func:`~arcosim.identification.fit.linear_model.
    solve_doubling`, Chu, Fan, Lin, *Linear Algebra Appl.* 396, 2005): quadratic
    convergence, a few small solves per step, ~20× faster here than
    ``scipy.linalg.solve_discrete_are`` (whose balancing and QZ step dominated the fit at
    4 kHz); it falls back on that when doubling does not converge.
    """
    size = len(A)
    G = np.zeros((size, size))
    G[0, 0] = 1.0 / R
    try:
        return solve_doubling(A.T, G, Q, iterations)
    except ConvergenceError:
        pass
    eye = np.eye(size)
    H = np.zeros((size, 1))
    H[0, 0] = 1.0
    return scipy.linalg.solve_discrete_are(A.T, H, Q + 1e-300 * eye, np.array([[R]]))


def innovations(record: EncoderRecord, drive: Drive) -> np.ndarray:
    """Normalized one-step prediction errors of the encoder angle (dimensionless: over
    their standard deviation) of ``drive`` on ``record``, shape ``(N − 1,)``."""
    kalman = Kalman.of(record, drive)
    predicted = kalman.predicted_angle(record, drive)[1:]
    y = record.theta_m[1:] - record.theta_m[0]
    return (y - predicted) / np.sqrt(kalman.variance)


def discrete_drive(record: EncoderRecord, drive: Drive) -> tuple[np.ndarray, np.ndarray]:
    """Motor + chain over one step of ``record`` (its step, motor inertia and load
    model) for ``drive``: state ``[θ_m, θ_1…θ_n, ω_m, ω_1…ω_n]`` (rad, rad/s; then the
    slow load's random walk, N·m; n = 0: the rigid drive, its load inertia on the
    motor), inputs (motor torque, load torque on the last mass;
    N·m) held over the step. Returns ``(A, Bd)``, shapes ``(S, S)`` and ``(S, 2)``."""
    m = len(drive.J) + 1
    inverse = 1.0 / np.array([record.J_m + drive.J_rigid, *drive.J])
    K = drive.coupling(drive.k)
    C = drive.coupling(drive.B)
    C[0, 0] += drive.D_m
    slow = record.load == "slow"
    size = 2 * m + slow
    Ac = np.zeros((size, size))
    Ac[:m, m : 2 * m] = np.eye(m)
    Ac[m : 2 * m, :m] = -inverse[:, None] * K
    Ac[m : 2 * m, m : 2 * m] = -inverse[:, None] * C
    if slow:
        Ac[2 * m - 1, 2 * m] = -inverse[-1]
    E = np.zeros((size, 2))
    E[m, 0] = inverse[0]
    E[2 * m - 1, 1] = -inverse[-1]  # the load torque opposes the motion
    return hold(Ac, E, record.h)
