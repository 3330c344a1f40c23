"""The motor's friction when only k_t and J_m are given (offline).

The DOB's τ̂_reac is then computed without friction, so it carries the friction's torque
through G(s). :func:`friction_start` estimates D_m and f_c from what the start chain
(the record's modes) leaves of τ̂, :func:`without_friction` takes that torque out of
τ̂, and :func:`friction_cleaned` does both and reads the modes again: the whole-chain
fit and the log's check start from there.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from arcosim.identification.fit.output_error import predict, through_g
from arcosim.identification.modes.detection import DetectedModes, Modes, detect_modes, modal_damping
from arcosim.identification.records.record import EncoderRecord, MotorRecord


def friction_cleaned(
    record: MotorRecord, encoder: EncoderRecord, modes: Modes, largest: int
) -> tuple[MotorRecord, float, float, DetectedModes]:
    """For a record whose τ̂_reac was computed without friction: the friction's start
    (:func:`friction_start`) from the chain of ``modes``, the record with it taken out
    of τ̂ (:func:`without_friction`), ``D_m`` (N·m·s/rad), ``f_c`` (N·m), and the modes
    that record shows (:func:`~arcosim.identification.modes.detection.detect_modes`, up to
    ``largest`` masses)."""
    J0, k0 = modes.chain()
    D_m, f_c = friction_start(record, encoder, J0, k0, modal_damping(J0, k0, modes))
    cleaned = without_friction(record, encoder, D_m, f_c)
    return cleaned, D_m, f_c, detect_modes(cleaned, largest)


def friction_start(
    record: MotorRecord, encoder: EncoderRecord, J: np.ndarray, k: np.ndarray, B: np.ndarray
) -> tuple[float, float]:
    """Start values ``(D_m, f_c)`` (N·m·s/rad, N·m) for a record whose τ̂_reac was
    computed without friction: what the start chain leaves of τ̂ is
    ``G[D_m ω + f_c sgn ω]``, linear in both (least squares; each at least a small
    positive value)."""

    def G(x: np.ndarray) -> np.ndarray:
        return through_g(x, record.g_dist, record.h)

    left = record.tau_hat - predict(record, J, k, B)
    omega = encoder.velocity
    X = np.column_stack([G(omega), G(np.sign(omega))])
    coef = np.linalg.lstsq(X[1:], left[1:], rcond=None)[0]
    torque = float(np.sqrt(np.mean(encoder.drive**2)))
    return max(float(coef[0]), 1e-9), max(float(coef[1]), 1e-3 * torque)


def without_friction(
    record: MotorRecord, encoder: EncoderRecord, D_m: float, f_c: float
) -> MotorRecord:
    """``record`` with ``G[D_m ω + f_c s]`` taken out of τ̂_reac (ω, s: the encoder
    record's velocity and friction sign)."""
    friction = D_m * encoder.velocity + f_c * encoder.sign
    friction[0] = 0.0
    tau = record.tau_hat - through_g(friction, record.g_dist, record.h)
    return replace(record, tau_hat=tau)
