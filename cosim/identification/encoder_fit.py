"""Prediction-error identification of the whole drive: from the motor current to the encoder.

Motor and chain are one linear model driven by the motor torque
``k_t i_a − f_c s_k`` (s_k the friction's sign over the step: first from the angle's
derivative smoothed without lag, then from the Kalman smoother's states, stuck-aware:
while the smoothed motor velocity stays below :data:`STUCK_VELOCITY_COUNTS` counts per
second, the friction is the torque that holds the motor, within ±f_c). The encoder
measures the motor angle with a uniform error of one count (variance q²/12), and an
unmodelled torque on the motor (the friction's error, current noise; standard
deviation :func:`torque_std`) is the process noise. The steady-state Kalman predictor
gives the innovations, and least squares on them is the prediction-error estimate
(Ljung, *System Identification*, ch. 7). Being a predictor of the encoder from the
current, it is consistent with the drive's own speed or position loop closed around
it (closed-loop data: the current then depends on the noise; the direct method).

Besides every J_i, k_i, B_i it can fit

* the motor's friction D_m, f_c (when the user gives only k_t and J_m:
  ``friction_given=False``); the values in the record are then the start;
* a load torque on the last mass: a constant τ_L (``load="constant"``), or a constant
  plus a random walk of :func:`load_std` per step that the Kalman filter tracks
  (``load="slow"``), for a load that drifts slower than the first mode.

k_t and J_m are given, not fitted: a relative error ε in both scales every J_i, k_i,
B_i, D_m, f_c and τ_L by (1 + ε) (the model is homogeneous in torque); an error in
J_m alone shows as an error of the first inertia mostly.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg
from scipy import optimize, signal

from arcosim.fmu.flexchain.chain import spring_matrix
from arcosim.fmu.flexchain.defaults import G_DIST, VELOCITY_SMOOTHING
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.errors import IdentificationError
from arcosim.identification.output_error import (
    Fit,
    MotorRecord,
    constant_step,
    decorrelation_lag,
    linear_recursion,
    newey_west_covariance,
    predict,
    smooth_velocity,
)

#: Floor of the process noise's standard deviation (N·m per step).
TORQUE_STD_FLOOR = 1e-4
#: Below this smoothed motor speed (encoder counts per second) the motor is taken as
#: stuck in the second pass: its friction is the torque that holds it (within ±f_c).
STUCK_VELOCITY_COUNTS = 20.0
#: Iterations of each least-squares pass (a start from the record's modes converges
#: in 5–15; a chain with a mode the record does not have wanders).
MAX_ITERATIONS = 40
#: Load choices: none, a constant torque, or a constant plus a slow random walk.
LOADS = ("none", "constant", "slow")
#: Random walk of a ``"slow"`` load (N·m per √s), relative to the rms drive torque.
LOAD_DRIFT = 0.05


@dataclass(frozen=True)
class EncoderRecord:
    """The drive's own signals for the prediction-error fit.

    Attributes:
        h: sample step (s).
        drive: ``k_t i_a`` over the step ending at each sample (N·m), shape (N,).
        velocity: motor velocity whose sign sets the Coulomb friction's (rad/s), (N,).
        theta_m: encoder angle at the middle of its count (rad), shape (N,).
        count: one encoder count (rad).
        J_m: motor inertia (kg·m²).
        D_m: motor viscous friction (N·m·s/rad): given, or the fit's start.
        f_c: motor Coulomb friction (N·m): given, or the fit's start.
        torque_std: process noise (N·m per step).
        friction_given: D_m and f_c are known; else they are fitted.
        load: one of :data:`LOADS`.
        load_std: random walk of a ``"slow"`` load (N·m per step).
        friction_sign: s_k over each step (−1 … 1), shape (N,); None: sgn(velocity).
    """

    h: float
    drive: np.ndarray
    velocity: np.ndarray
    theta_m: np.ndarray
    count: float
    J_m: float
    D_m: float
    f_c: float
    torque_std: float
    friction_given: bool = True
    load: str = "none"
    load_std: float = 0.0
    friction_sign: np.ndarray | None = None

    @property
    def sign(self) -> np.ndarray:
        """s_k (−1 … 1) over the step ending at sample k, shape (N,): given, or the
        mean of sgn ω over the step with ω linear between samples (:func:`mean_sign`)."""
        return mean_sign(self.velocity) if self.friction_sign is None else self.friction_sign

    @property
    def torque(self) -> np.ndarray:
        """``k_t i_a − f_c s_k`` (N·m), shape (N,)."""
        return self.drive - self.f_c * self.sign

    @property
    def duration(self) -> float:
        return self.h * (len(self.theta_m) - 1)


def encoder_record(
    time: np.ndarray,
    i_a: np.ndarray,
    theta_m: np.ndarray,
    actuator: Actuator,
    cpr: int,
    friction_given: bool = True,
    load: str = "none",
    g_dist: float = G_DIST,
) -> EncoderRecord:
    """The record of the prediction-error fit: the current in, the encoder's counts out.

    The friction's sign comes from the angle's derivative smoothed without lag at
    ``VELOCITY_SMOOTHING · g_dist``, as the motor record's DOB velocity (the second
    pass of :func:`refine` replaces it). With ``friction_given=False`` the actuator's
    D_m, f_c are ignored and the fit starts from a rigid-body estimate
    (:func:`rigid_friction`).

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``, a constant step.
    i_a : ndarray
        Current (A), shape ``(N,)``, the current that acted over each step.
    theta_m : ndarray
        Motor angle as the encoder gives it (rad, whole counts), shape ``(N,)``.
    actuator : Actuator
        The motor's terms (J_mo kg·m², k_to N·m/A, D_m N·m·s/rad, f_c N·m).
    cpr : int
        The encoder's counts per revolution (a count), > 0.
    friction_given : bool
        Whether the actuator's D_m and f_c are known (else they are fitted).
    load : {"none", "constant", "slow"}
        The load torque the model carries on the last mass.
    g_dist : float
        The DOB's bandwidth (rad/s), for the friction sign's smoothing.

    Returns
    -------
    EncoderRecord
        The drive torque (N·m), the counts' angle (rad) and their resolution (rad),
        the friction model and its start, each array of shape ``(N,)``.

    Raises
    ------
    IdentificationError
        For an encoder without counts (``cpr`` ≤ 0), a varying step or an unknown
        ``load``.

    Examples
    --------
    >>> t = np.arange(1000) * 1e-3
    >>> counts = 2.0 * np.pi / 2000
    >>> theta = np.floor(np.sin(3.0 * t) / counts) * counts
    >>> motor = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406)
    >>> record = arcosim.encoder_record(t, 0.1 * np.sin(3.0 * t), theta, motor, 2000)
    >>> record.h, float(record.count) == counts
    (0.001, True)
    """
    if cpr <= 0:
        raise IdentificationError(
            "the prediction-error fit needs the encoder's counts per revolution"
        )
    if load not in LOADS:
        raise IdentificationError(f"load must be one of {', '.join(LOADS)}, got {load!r}")
    h = constant_step(time)
    count = 2.0 * np.pi / cpr
    theta = np.asarray(theta_m, dtype=float) + count / 2.0
    drive = (actuator.k_to + actuator.dkt) * np.asarray(i_a, dtype=float)
    cutoff = VELOCITY_SMOOTHING * g_dist
    velocity = smooth_velocity(theta, h, cutoff)
    J_m = actuator.J_mo + actuator.dJm
    D_m, f_c = actuator.D_m, actuator.f_c
    if not friction_given:
        D_m, f_c = rigid_friction(drive, theta, velocity, h)
    drift = LOAD_DRIFT * float(np.sqrt(np.mean(drive**2))) * np.sqrt(h)
    return EncoderRecord(
        h=h,
        drive=drive,
        velocity=velocity,
        theta_m=theta,
        count=count,
        J_m=J_m,
        D_m=D_m,
        f_c=f_c,
        torque_std=torque_std(f_c),
        friction_given=friction_given,
        load=load,
        load_std=drift if load == "slow" else 0.0,
    )


def opening(record: EncoderRecord, seconds: float) -> EncoderRecord:
    """The first ``seconds`` of ``record`` (all of it if shorter)."""
    count = min(len(record.theta_m), round(seconds / record.h) + 1)
    sign = None if record.friction_sign is None else record.friction_sign[:count]
    return replace(
        record,
        drive=record.drive[:count],
        velocity=record.velocity[:count],
        theta_m=record.theta_m[:count],
        friction_sign=sign,
    )


def rigid_friction(
    drive: np.ndarray, theta: np.ndarray, velocity: np.ndarray, h: float
) -> tuple[float, float]:
    """Start values ``(D_m, f_c)`` from the record read as one rigid body: below a
    few rad/s the chain moves with the motor, so ``k_t i ≈ J_total α + D_m ω + f_c sgn ω``;
    least squares on the signals low-passed at 2 rad/s (J_total fitted too); sgn ω from
    the record's smoothed ``velocity`` (rad/s)."""
    cutoff = 2.0
    b, a = signal.butter(2, min(cutoff * h / np.pi, 0.5))
    torque = signal.filtfilt(b, a, drive)
    angle = signal.filtfilt(b, a, theta)
    omega = np.gradient(angle, h)
    alpha = np.gradient(omega, h)
    sign = signal.filtfilt(b, a, np.sign(velocity))
    X = np.column_stack([alpha, omega, sign])
    coef = np.linalg.lstsq(X, torque, rcond=None)[0]
    scale = float(np.sqrt(np.mean(drive**2)))
    D_m = float(np.clip(coef[1], 1e-6 * scale, None))
    f_c = float(np.clip(coef[2], 1e-3 * scale, None))
    return D_m, f_c


def mean_sign(velocity: np.ndarray) -> np.ndarray:
    """Mean of sgn ω over each step ending at a sample, ω linear between samples (a
    reversal inside a step counts for the fraction of the step on each side); sample 0
    takes its own sign. Shape (N,)."""
    w0, w1 = velocity[:-1], velocity[1:]
    s0, s1 = np.sign(w0), np.sign(w1)
    out = np.sign(s0 + s1)  # no reversal: the sign of the end that moves (0 if neither)
    cross = s0 * s1 < 0
    r = w0[cross] / (w0[cross] - w1[cross])  # fraction of the step before the reversal
    out[cross] = s0[cross] * (2.0 * r - 1.0)
    return np.concatenate([[np.sign(velocity[0])], out])


def torque_std(f_c: float) -> float:
    """Unmodelled motor torque (N·m per step): half the Coulomb friction ``f_c`` (N·m;
    what the friction model misses while the motor sticks), at least
    :data:`TORQUE_STD_FLOOR`."""
    return max(f_c / 2.0, TORQUE_STD_FLOOR)


def with_friction(record: EncoderRecord, D_m: float, f_c: float) -> EncoderRecord:
    """``record`` with the motor friction ``D_m`` (N·m·s/rad), ``f_c`` (N·m) and the
    process noise that goes with it (:func:`torque_std`)."""
    return replace(record, D_m=D_m, f_c=f_c, torque_std=torque_std(f_c))


@dataclass(frozen=True)
class Drive:
    """One drive model: chain, motor friction, load torque (SI units)."""

    J: np.ndarray
    k: np.ndarray
    B: np.ndarray
    D_m: float
    f_c: float
    tau_load: float = 0.0


def parameter_names(n: int, record: EncoderRecord) -> list[str]:
    """Fit order: ``J[i]``, ``k[i]``, ``B[i]``, then ``D_m``, ``f_c`` (friction not given),
    then ``tau_load`` (a load torque modelled)."""
    names = [f"{p}[{i}]" for p in ("J", "k", "B") for i in range(1, n + 1)]
    if not record.friction_given:
        names += ["D_m", "f_c"]
    if record.load != "none":
        names.append("tau_load")
    return names


def unpack(p: np.ndarray, n: int, record: EncoderRecord) -> Drive:
    """The drive of parameter vector ``p`` (:func:`parameter_names` order)."""
    J, k, B = p[:n], p[n : 2 * n], p[2 * n : 3 * n]
    j = 3 * n
    D_m, f_c = record.D_m, record.f_c
    if not record.friction_given:
        D_m, f_c = p[j], p[j + 1]
        j += 2
    tau = p[j] if record.load != "none" else 0.0
    return Drive(J, k, B, float(D_m), float(f_c), float(tau))


def pack(drive: Drive, record: EncoderRecord) -> np.ndarray:
    """Inverse of :func:`unpack`."""
    p = [*drive.J, *drive.k, *drive.B]
    if not record.friction_given:
        p += [drive.D_m, drive.f_c]
    if record.load != "none":
        p.append(drive.tau_load)
    return np.array(p, dtype=float)


@dataclass(frozen=True)
class _Kalman:
    """Steady-state Kalman filter of motor + chain (state ``[θ_m, θ_1…θ_n, ω_m, …]``,
    then the load's random walk when ``load="slow"``)."""

    A: np.ndarray
    Bd: np.ndarray  # columns: motor torque, load torque on the last mass
    prior: np.ndarray  # P⁻ (rad², …)
    variance: float  # of the innovation (rad²)
    gain: np.ndarray  # filter gain P⁻Hᵀ/S

    @classmethod
    def of(cls, record: EncoderRecord, drive: Drive) -> _Kalman:
        A, Bd = _discrete(record, drive)
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

    Structure-preserving doubling (Chu, Fan, Lin, *Linear Algebra Appl.* 396, 2005):
    quadratic convergence, a few small solves per step, ~20× faster here than
    ``scipy.linalg.solve_discrete_are`` (whose balancing and QZ step dominated the fit at
    4 kHz); it falls back on that when doubling does not converge.
    """
    size = len(A)
    Ak = A.T.copy()
    G = np.zeros((size, size))
    G[0, 0] = 1.0 / R
    X = Q.copy()
    eye = np.eye(size)
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
    H = np.zeros((size, 1))
    H[0, 0] = 1.0
    return scipy.linalg.solve_discrete_are(A.T, H, Q + 1e-300 * eye, np.array([[R]]))


def output_recursion(F: np.ndarray, G: np.ndarray, u: np.ndarray) -> np.ndarray:
    """First state of ``x_0 = 0``, ``x_{j+1} = F x_j + G u_j`` (shape (M + 1,)), in modal
    coordinates, only the first state formed: a real eigenvalue is one first-order
    ``lfilter``, a conjugate pair one real second-order ``lfilter`` (its inputs combined
    beforehand), so the cost is a few real filters over the record."""
    lam, V = np.linalg.eig(F)
    weights = V[0, :, None] * np.linalg.solve(V, np.asarray(G, dtype=complex))  # (S, I)
    out = np.zeros(u.shape[1] + 1)
    done = np.zeros(len(lam), dtype=bool)
    for j, root in enumerate(lam):
        if done[j]:
            continue
        done[j] = True
        if abs(root.imag) <= 1e-12 * max(abs(root), 1e-300):
            out[1:] += signal.lfilter([1.0], [1.0, -root.real], weights[j].real @ u)
            continue
        partner = np.flatnonzero(~done & (np.abs(lam - np.conj(root)) <= 1e-9 * abs(root)))
        if partner.size:
            done[partner[0]] = True
        # c/(1 − λz⁻¹) + c̄/(1 − λ̄z⁻¹) = (2 Re c − 2 Re(c λ̄) z⁻¹) / (1 − 2 Re λ z⁻¹ + |λ|² z⁻²)
        b0 = 2.0 * weights[j].real @ u
        b1 = -2.0 * (weights[j] * np.conj(root)).real @ u
        v = b0.copy()
        v[1:] += b1[:-1]
        out[1:] += signal.lfilter([1.0], [1.0, -2.0 * root.real, abs(root) ** 2], v)
    return out


def innovations(record: EncoderRecord, drive: Drive) -> np.ndarray:
    """Normalized one-step prediction errors of the encoder angle, shape (N − 1,)."""
    kalman = _Kalman.of(record, drive)
    predicted = kalman.predicted_angle(record, drive)[1:]
    y = record.theta_m[1:] - record.theta_m[0]
    return (y - predicted) / np.sqrt(kalman.variance)


def _discrete(record: EncoderRecord, drive: Drive) -> tuple[np.ndarray, np.ndarray]:
    """Motor + chain, state ``[θ_m, θ_1…θ_n, ω_m, ω_1…ω_n]`` (then the slow load's
    random walk), inputs (motor torque, load torque on the last mass) held over a step."""
    m = len(drive.J) + 1
    inverse = 1.0 / np.array([record.J_m, *drive.J])
    K = np.array(spring_matrix([float(x) for x in drive.k]))
    C = np.array(spring_matrix([float(x) for x in drive.B]))
    C[0, 0] += drive.D_m
    slow = record.load == "slow"
    size = 2 * m + slow
    Ac = np.zeros((size, size))
    Ac[:m, m : 2 * m] = np.eye(m)
    Ac[m : 2 * m, :m] = -inverse[:, None] * K
    Ac[m : 2 * m, m : 2 * m] = -inverse[:, None] * C
    if slow:
        Ac[2 * m - 1, 2 * m] = -inverse[-1]
    augmented = np.zeros((size + 2, size + 2))
    augmented[:size, :size] = Ac
    augmented[m, size] = inverse[0]
    augmented[2 * m - 1, size + 1] = -inverse[-1]  # the load torque opposes the motion
    X = scipy.linalg.expm(augmented * record.h)
    return X[:size, :size], X[:size, size:]


def stuck_aware_sign(record: EncoderRecord, drive: Drive, states: np.ndarray) -> np.ndarray:
    """The friction's s_k from smoothed states (N, S): sgn ω where the motor moves;
    where it is stuck (|ω| below :data:`STUCK_VELOCITY_COUNTS` counts/s) the share of
    f_c that holds it, ``clip((k_t i − spring and damper torques)/f_c, −1, 1)``."""
    n = len(drive.J)
    m = n + 1
    omega = states[:, m]
    spring = drive.k[0] * (states[:, 0] - states[:, 1]) + drive.B[0] * (omega - states[:, m + 1])
    other = record.drive - drive.D_m * omega - spring
    sign = mean_sign(omega)
    stuck = np.abs(omega) < STUCK_VELOCITY_COUNTS * record.count
    if drive.f_c > 0:
        sign[stuck] = np.clip(other[stuck] / drive.f_c, -1.0, 1.0)
    return sign


def refine(record: EncoderRecord, motor: MotorRecord | None, start: Fit, n: int) -> Fit:
    """Prediction-error fit of the drive from ``start`` (an n-mass fit whose first 3n
    values are J_i, k_i, B_i; ``motor``, the same log's τ̂_reac record, only for the
    reported τ̂ residual), in two passes: the friction's sign first from the record's
    velocity, then stuck-aware from the Kalman smoother's states with the first pass's
    drive (:func:`stuck_aware_sign`).

    Standard errors: Newey–West on the innovations' score (they are nearly white).
    """
    chain = np.asarray(start.values[: 3 * n], dtype=float).copy()
    floor = 1e-3 * np.mean(chain[2 * n :]) if np.any(chain[2 * n :] > 0) else 1e-9
    chain[2 * n :] = np.maximum(chain[2 * n :], floor)
    first = pack(Drive(chain[:n], chain[n : 2 * n], chain[2 * n :], record.D_m, record.f_c), record)
    values, residual, jac, evaluations = _least_squares(record, first, n)
    drive = unpack(values, n, record)
    with np.errstate(all="ignore"):
        states = _Kalman.of(record, drive).smoothed(record, drive)
    more = 0
    if np.all(np.isfinite(states)):  # else the first pass's drive is no chain to smooth with
        record = replace(
            record,
            friction_sign=stuck_aware_sign(record, drive, states),
            velocity=states[:, n + 1],
        )
        values, residual, jac, more = _least_squares(record, values, n)
    drive = unpack(values, n, record)
    lag = decorrelation_lag(residual, 1)
    std = np.sqrt(np.clip(np.diag(newey_west_covariance(jac, residual, lag)), 0.0, None))
    extra = {
        **start.extra,
        "information_criterion": innovation_criterion(residual, len(values)),
        "start_fit": start.as_dict(),
        "innovation_variance": float(np.mean(residual**2)),
        "torque_std": record.torque_std,
        "friction": "given" if record.friction_given else "fitted",
        "load": record.load,
        "D_m": drive.D_m,
        "f_c": drive.f_c,
    }
    if record.load == "slow":
        states = _Kalman.of(record, drive).smoothed(record, drive)
        load = drive.tau_load + states[:, -1]
        extra["load_torque_range"] = [float(load.min()), float(load.max())]
    rms = start.rms_residual
    if motor is not None:
        tau_residual = predict(motor, drive.J, drive.k, drive.B) - motor.tau_hat
        rms = float(np.sqrt(np.mean(tau_residual**2)))
    return Fit(
        names=parameter_names(n, record),
        values=values,
        std=std,
        start=first,
        start_note=start.start_note
        + "; then the prediction-error fit from the current to the encoder",
        rms_residual=rms,
        rms_data=start.rms_data,
        lag=lag,
        evaluations=start.evaluations + evaluations + more,
        extra=extra,
    )


def innovation_criterion(innovations: np.ndarray, parameters: int) -> float:
    """Bayesian information criterion of a prediction-error fit: ``N log(mean e²) +
    P log N`` on the normalized innovations (nearly white, so N counts samples)."""
    count = len(innovations)
    return float(count * np.log(np.mean(innovations**2)) + parameters * np.log(count))


def _least_squares(
    record: EncoderRecord, first: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Least squares on the innovations from ``first``: the values, the innovations,
    their Jacobian by parameter (N − 1, P) and the model runs used. Each parameter is
    scaled by its start (the load torque by the rms drive torque / 100: it may be 0)."""
    names = parameter_names(n, record)
    scale = np.abs(first).astype(float)
    lower = np.zeros(len(first))
    lower[: 2 * n] = 1e-3  # inertias and stiffnesses above a thousandth of their start
    if record.load != "none":
        torque = float(np.sqrt(np.mean(record.drive**2)))
        scale[-1] = max(abs(first[-1]), 1e-2 * torque)
        lower[-1] = -np.inf
    for j, name in enumerate(names):
        if name in ("D_m", "f_c"):
            scale[j] = max(scale[j], 1e-9)
    x0 = first / scale

    def residual(x: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            e = innovations(record, unpack(x * scale, n, record))
        if not np.all(np.isfinite(e)):
            raise IdentificationError(
                f"the prediction-error fit of {n} mass(es) diverged (the record does not "
                "determine that chain): excite the modes better or fit fewer masses"
            )
        return e

    result = optimize.least_squares(
        residual,
        x0,
        bounds=(lower, np.inf),
        x_scale="jac",
        diff_step=1e-6,
        max_nfev=MAX_ITERATIONS,
    )
    runs = int(result.nfev * (len(first) + 1))
    return result.x * scale, result.fun, result.jac / scale, runs
