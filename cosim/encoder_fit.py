"""Prediction-error refinement of the whole chain: from the motor current to the encoder.

The output-error fit (:mod:`cosim.output_error`) drives the chain model with the
encoder's angle, so the counts are an error in the model's *input*: they bias every
B_i by tens of percent (the same on every seed) and pull J_i, k_i low by up to 1 %.
Here the counts are where they belong, in the *output*: motor and chain are one
linear model driven by the motor torque ``k_t i_a − f_c sgn(ω)`` (ω: the angle's
derivative smoothed without lag, as for the DOB), the encoder measures the motor
angle with a uniform error of one count (variance q²/12), and an unmodelled torque on
the motor (the friction's error while the motor sticks, current noise; standard
deviation :func:`torque_std`) is the process noise. The steady-state Kalman predictor
gives the innovations, and least squares on them is the prediction-error estimate
(Ljung, *System Identification*, ch. 7), started from the output-error fit. Measured on
the accuracy benchmark's chains (README): J_i and k_i within 0.3 %, B_i within a few
percent.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from scipy import optimize, signal

from cosim.errors import UserError
from cosim.output_error import (
    Fit,
    MotorRecord,
    constant_step,
    decorrelation_lag,
    newey_west_covariance,
    predict,
    smooth_velocity,
)
from flexchain.chain import spring_matrix
from flexchain.dob import Actuator

#: Floor of the process noise's standard deviation (N·m per step): the observer FMU's
#: default unmodelled torque.
TORQUE_STD_FLOOR = 1e-4


@dataclass(frozen=True)
class EncoderRecord:
    """The drive's own signals for the prediction-error fit.

    Attributes:
        h: sample step (s).
        torque: ``k_t i_a − f_c sgn(ω)`` over the step ending at each sample (N·m), (N,).
        theta_m: encoder angle at the middle of its count (rad), shape (N,).
        count: one encoder count (rad).
        J_m: motor inertia (kg·m²).
        D_m: motor viscous friction (N·m·s/rad).
        torque_std: process noise (N·m per step).
    """

    h: float
    torque: np.ndarray
    theta_m: np.ndarray
    count: float
    J_m: float
    D_m: float
    torque_std: float


def encoder_record(
    time: np.ndarray, i_a: np.ndarray, theta_m: np.ndarray, actuator: Actuator, cpr: int
) -> EncoderRecord:
    """Build the record from a log (``theta_m`` as the encoder gives it: whole counts).

    Raises:
        UserError: for an encoder without counts (``cpr`` ≤ 0) or a varying step.
    """
    if cpr <= 0:
        raise UserError("the prediction-error fit needs the encoder's counts per revolution")
    h = constant_step(time)
    count = 2.0 * np.pi / cpr
    theta = np.asarray(theta_m, dtype=float) + count / 2.0
    velocity = smooth_velocity(theta, h, 400.0)
    k_t = actuator.k_to + actuator.dkt
    torque = k_t * np.asarray(i_a, dtype=float) - actuator.f_c * np.sign(velocity)
    J_m = actuator.J_mo + actuator.dJm
    return EncoderRecord(h, torque, theta, count, J_m, actuator.D_m, torque_std(actuator))


def torque_std(actuator: Actuator) -> float:
    """Unmodelled motor torque (N·m per step): half the Coulomb friction (what the
    friction model misses while the motor sticks), at least :data:`TORQUE_STD_FLOOR`."""
    return max(actuator.f_c / 2.0, TORQUE_STD_FLOOR)


def innovations(
    record: EncoderRecord, J: Sequence[float], k: Sequence[float], B: Sequence[float]
) -> np.ndarray:
    """Normalized one-step prediction errors of the encoder angle, shape (N − 1,)."""
    A, Bd = _discrete(record, J, k, B)
    size = len(Bd)
    H = np.zeros((1, size))
    H[0, 0] = 1.0
    Q = np.outer(Bd, Bd) * record.torque_std**2
    R = np.array([[record.count**2 / 12.0]])
    P = scipy.linalg.solve_discrete_are(A.T, H.T, Q + 1e-300 * np.eye(size), R)
    S = float((H @ P @ H.T + R)[0, 0])
    gain = A @ (P[:, 0] / S)
    F = A - np.outer(gain, H[0])  # x⁻_{k+1} = F x⁻_k + A K y_k + Bd u_{k+1}
    y = record.theta_m
    forcing = np.outer(gain, y[:-1]) + np.outer(Bd, record.torque[1:])
    start = np.zeros(size)
    start[: len(J) + 1] = y[0]  # at rest, aligned with the motor
    lam, V = np.linalg.eig(F)
    modal_forcing = np.linalg.solve(V, forcing.astype(complex))
    modal_start = np.linalg.solve(V, start.astype(complex))
    modal = np.empty_like(modal_forcing)
    for j, root in enumerate(lam):
        modal[j], _ = signal.lfilter(
            [1.0], [1.0, -root], modal_forcing[j], zi=[root * modal_start[j]]
        )
    predicted = (V[0] @ modal).real
    return (y[1:] - predicted) / np.sqrt(S)


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
    fit to ``motor``, the same log's τ̂_reac record).

    Standard errors: Newey–West on the innovations' score (they are nearly white).
    ``rms_residual`` stays that of τ̂_reac, now with the refined chain.
    """
    first = np.asarray(start.values, dtype=float).copy()
    floor = 1e-3 * np.mean(first[2 * n :]) if np.any(first[2 * n :] > 0) else 1e-9
    first[2 * n :] = np.maximum(first[2 * n :], floor)

    def residual(scaled: np.ndarray) -> np.ndarray:
        p = scaled * first
        return innovations(record, p[:n], p[n : 2 * n], p[2 * n :])

    lower = np.concatenate([np.full(2 * n, 1e-3), np.zeros(n)])
    result = optimize.least_squares(
        residual, np.ones_like(first), bounds=(lower, np.inf), x_scale="jac", diff_step=1e-6
    )
    values = result.x * first
    jac = result.jac / first
    tau_residual = predict(motor, values[:n], values[n : 2 * n], values[2 * n :]) - motor.tau_hat
    lag = decorrelation_lag(result.fun, 1)
    std = np.sqrt(np.clip(np.diag(newey_west_covariance(jac, result.fun, lag)), 0.0, None))
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
        evaluations=start.evaluations + int(result.nfev * (len(first) + 1)),
        extra={
            **start.extra,
            "output_error": start.as_dict(),
            "innovation_variance": float(np.mean(result.fun**2)),
            "torque_std": record.torque_std,
        },
    )
