"""Prediction-error refinement of the whole chain: from the motor current to the encoder.

The output-error fit (:mod:`cosim.output_error`) drives the chain model with the
encoder's angle, so the counts are an error in the model's *input*: they bias every
B_i by tens of percent (the same on every seed) and pull J_i, k_i low by up to 1 %.
Here the counts are where they belong, in the *output*: motor and chain are one
linear model driven by the motor torque ``k_t i_a − f_c sgn(ω)`` (ω: first the
angle's derivative smoothed without lag, then the Kalman smoother's motor velocity),
the encoder measures the motor angle with a uniform error of one count (variance
q²/12), and an unmodelled torque on
the motor (the friction's error while the motor sticks, current noise; standard
deviation :func:`torque_std`) is the process noise. The steady-state Kalman predictor
gives the innovations, and least squares on them is the prediction-error estimate
(Ljung, *System Identification*, ch. 7), started from the output-error fit, in two
passes (:func:`refine`). Measured on the accuracy benchmark's three chains, 20 seeds
each (README): J_i and k_i within 0.35 %, every B_i within two standard errors.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg
from scipy import optimize

from arcosim.errors import UserError
from arcosim.fmu.flexchain.chain import spring_matrix
from arcosim.fmu.flexchain.dob import Actuator
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

#: Cutoff (rad/s) of the lag-free smoothing whose derivative gives the first pass its
#: friction sign: the DOB's 4·g_dist at the default g_dist of 100 rad/s.
SIGN_VELOCITY_CUTOFF = 400.0
#: Floor of the process noise's standard deviation (N·m per step): the observer FMU's
#: default unmodelled torque.
TORQUE_STD_FLOOR = 1e-4


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
        D_m: motor viscous friction (N·m·s/rad).
        f_c: motor Coulomb friction (N·m).
        torque_std: process noise (N·m per step).
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

    @property
    def torque(self) -> np.ndarray:
        """``k_t i_a − f_c sgn(ω)`` (N·m), shape (N,)."""
        return self.drive - self.f_c * np.sign(self.velocity)


def encoder_record(
    time: np.ndarray, i_a: np.ndarray, theta_m: np.ndarray, actuator: Actuator, cpr: int
) -> EncoderRecord:
    """Build the record from a log (``theta_m`` as the encoder gives it: whole counts);
    the friction's sign from the angle's derivative smoothed without lag at
    :data:`SIGN_VELOCITY_CUTOFF` (the second pass of :func:`refine` replaces it).

    Raises:
        UserError: for an encoder without counts (``cpr`` ≤ 0) or a varying step.
    """
    if cpr <= 0:
        raise UserError("the prediction-error fit needs the encoder's counts per revolution")
    h = constant_step(time)
    count = 2.0 * np.pi / cpr
    theta = np.asarray(theta_m, dtype=float) + count / 2.0
    return EncoderRecord(
        h=h,
        drive=(actuator.k_to + actuator.dkt) * np.asarray(i_a, dtype=float),
        velocity=smooth_velocity(theta, h, SIGN_VELOCITY_CUTOFF),
        theta_m=theta,
        count=count,
        J_m=actuator.J_mo + actuator.dJm,
        D_m=actuator.D_m,
        f_c=actuator.f_c,
        torque_std=torque_std(actuator),
    )


def torque_std(actuator: Actuator) -> float:
    """Unmodelled motor torque (N·m per step): half the Coulomb friction (what the
    friction model misses while the motor sticks), at least :data:`TORQUE_STD_FLOOR`."""
    return max(actuator.f_c / 2.0, TORQUE_STD_FLOOR)


@dataclass(frozen=True)
class _Kalman:
    """Steady-state Kalman filter of motor + chain (state ``[θ_m, θ_1…θ_n, ω_m, …]``)."""

    A: np.ndarray
    Bd: np.ndarray
    prior: np.ndarray  # P⁻ (rad², …)
    variance: float  # of the innovation (rad²)
    gain: np.ndarray  # filter gain P⁻Hᵀ/S

    @classmethod
    def of(cls, record: EncoderRecord, chain: Sequence[Sequence[float]]) -> _Kalman:
        A, Bd = _discrete(record, *chain)
        size = len(Bd)
        H = np.zeros((1, size))
        H[0, 0] = 1.0
        Q = np.outer(Bd, Bd) * record.torque_std**2
        R = np.array([[record.count**2 / 12.0]])
        P = scipy.linalg.solve_discrete_are(A.T, H.T, Q + 1e-300 * np.eye(size), R)
        S = float(P[0, 0] + R[0, 0])
        return cls(A, Bd, P, S, P[:, 0] / S)

    def predicted(self, record: EncoderRecord, n: int) -> np.ndarray:
        """x⁻_0 … x⁻_{N−1}, each state before its sample's reading (x⁻_0: at rest,
        aligned with the motor's first reading), shape (N, 2n + 2)."""
        y = record.theta_m
        gain = self.A @ self.gain
        F = self.A - np.outer(gain, np.eye(len(gain))[0])  # x⁻_{k+1} = F x⁻_k + …
        inputs = np.vstack([y[:-1], record.torque[1:]])
        start = np.zeros(len(gain))
        start[: n + 1] = y[0]
        return linear_recursion(F, np.column_stack([gain, self.Bd]), inputs, start).T

    def smoothed(self, record: EncoderRecord, n: int) -> np.ndarray:
        """Rauch–Tung–Striebel smoothed states x_0 … x_{N−1}, shape (N, 2n + 2)."""
        before = self.predicted(record, n)
        after = before + np.outer(record.theta_m - before[:, 0], self.gain)  # filtered
        posterior = self.prior - np.outer(self.gain, self.prior[0])
        G = posterior @ self.A.T @ np.linalg.inv(self.prior)
        # backward: xs_k = G xs_{k+1} + (x_k − G x⁻_{k+1}), from xs_{N−1} = x_{N−1}
        inputs = np.hstack([after[:-1], before[1:]])[::-1].T
        both = np.hstack([np.eye(len(G)), -G])
        return linear_recursion(G, both, inputs, after[-1]).T[::-1]


def innovations(
    record: EncoderRecord, J: Sequence[float], k: Sequence[float], B: Sequence[float]
) -> np.ndarray:
    """Normalized one-step prediction errors of the encoder angle, shape (N − 1,)."""
    kalman = _Kalman.of(record, (J, k, B))
    predicted = kalman.predicted(record, len(J))[1:]
    return (record.theta_m[1:] - predicted[:, 0]) / np.sqrt(kalman.variance)


def _discrete(
    record: EncoderRecord, J: Sequence[float], k: Sequence[float], B: Sequence[float]
) -> tuple[np.ndarray, np.ndarray]:
    """Motor + chain, state ``[θ_m, θ_1…θ_n, ω_m, ω_1…ω_n]``, torque held over a step."""
    m = len(J) + 1
    inverse = 1.0 / np.array([record.J_m, *J])
    K = np.array(spring_matrix([float(x) for x in k]))
    C = np.array(spring_matrix([float(x) for x in B]))
    C[0, 0] += record.D_m
    Ac = np.block([[np.zeros((m, m)), np.eye(m)], [-inverse[:, None] * K, -inverse[:, None] * C]])
    augmented = np.zeros((2 * m + 1, 2 * m + 1))
    augmented[: 2 * m, : 2 * m] = Ac
    augmented[m, 2 * m] = inverse[0]
    X = scipy.linalg.expm(augmented * record.h)
    return X[: 2 * m, : 2 * m], X[: 2 * m, 2 * m]


def refine(record: EncoderRecord, motor: MotorRecord, start: Fit, n: int) -> Fit:
    """Prediction-error fit of every J_i, k_i, B_i from ``start`` (an n-mass output-error
    fit to ``motor``, the same log's τ̂_reac record), in two passes: the friction's sign
    first from the record's velocity, then from the Kalman smoother's motor velocity
    with the first pass's chain (the smoothed angle's derivative flips sign late at
    reversals, an error with the sign of the velocity that the fit took for damping:
    B_1 of the five-mass chain +8 %, +3 % after the second pass).

    Standard errors: Newey–West on the innovations' score (they are nearly white).
    ``rms_residual`` is that of τ̂_reac with the refined chain.
    """
    first = np.asarray(start.values, dtype=float).copy()
    floor = 1e-3 * np.mean(first[2 * n :]) if np.any(first[2 * n :] > 0) else 1e-9
    first[2 * n :] = np.maximum(first[2 * n :], floor)
    values, _, _, evaluations = _least_squares(record, first, n)
    kalman = _Kalman.of(record, (values[:n], values[n : 2 * n], values[2 * n :]))
    velocity = kalman.smoothed(record, n)[:, n + 1]
    record = replace(record, velocity=velocity)
    values, residual, jac, more = _least_squares(record, values, n)
    tau_residual = predict(motor, values[:n], values[n : 2 * n], values[2 * n :]) - motor.tau_hat
    lag = decorrelation_lag(residual, 1)
    std = np.sqrt(np.clip(np.diag(newey_west_covariance(jac, residual, lag)), 0.0, None))
    return Fit(
        names=list(start.names),
        values=values,
        std=std,
        start=start.values,
        start_note=start.start_note
        + "; then the prediction-error fit from the current to the encoder",
        rms_residual=float(np.sqrt(np.mean(tau_residual**2))),
        rms_data=start.rms_data,
        lag=lag,
        evaluations=start.evaluations + evaluations + more,
        extra={
            **start.extra,
            "output_error": start.as_dict(),
            "innovation_variance": float(np.mean(residual**2)),
            "torque_std": record.torque_std,
        },
    )


def _least_squares(
    record: EncoderRecord, first: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Least squares on the innovations from ``first`` (> 0): the values, the
    innovations, their Jacobian by parameter (N − 1, 3n) and the model runs used."""

    def residual(scaled: np.ndarray) -> np.ndarray:
        p = scaled * first
        return innovations(record, p[:n], p[n : 2 * n], p[2 * n :])

    lower = np.concatenate([np.full(2 * n, 1e-3), np.zeros(n)])
    result = optimize.least_squares(
        residual, np.ones_like(first), bounds=(lower, np.inf), x_scale="jac", diff_step=1e-6
    )
    runs = int(result.nfev * (len(first) + 1))
    return result.x * first, result.fun, result.jac / first, runs
