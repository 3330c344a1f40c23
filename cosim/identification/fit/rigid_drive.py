"""The rigid drive (n = 0): motor and load one body, no mode in the band (offline).

A ball-screw axis or a stiff coupling shows no resonance below the band; its log then
fixes the load inertia ``J_load = J_total − J_m`` (kg·m²), the motor's friction and a
load torque, and nothing else. :func:`rigid_fit` fits them by the same
prediction-error fit from the current to the encoder the chains use
(:func:`~arcosim.identification.fit.encoder_fit.refine` with n = 0), from a start read by
least squares on the rigid body's torque balance (:func:`rigid_start`).
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from arcosim.identification.fit.encoder_fit import RIGID_LOAD, refine
from arcosim.identification.fit.output_error import ParameterFit, rigid_predict
from arcosim.identification.records.record import EncoderRecord, MotorRecord

#: Low-pass (rad/s) of the rigid start's torque balance: well below the encoder's
#: noise, well above the record's lowest lines.
RIGID_CUTOFF = 20.0


def rigid_start(record: EncoderRecord) -> float:
    """Start value of ``J_load`` (kg·m²): least squares on ``k_t i = J_total α + D_m ω +
    f_c sgn ω`` low-passed at :data:`RIGID_CUTOFF` (forward and backward), less J_m;
    at least a hundredth of J_m (the fit's scale must be > 0).

    Examples
    --------
    >>> t = np.arange(5000) * 1e-3
    >>> theta = np.sin(5 * t)
    >>> drive = 3e-4 * -25 * np.sin(5 * t)  # J_total = 3e-4, no friction
    >>> from arcosim.identification.records.record import EncoderRecord
    >>> record = EncoderRecord(1e-3, drive, 5 * np.cos(5 * t), theta, 1e-6, 1e-4, 0, 0, 1e-4)
    >>> round(rigid_start(record) / 1e-4, 2)  # J_total − J_m, in 1e-4 kg·m²
    2.0
    """
    h = record.h
    b, a = signal.butter(2, min(RIGID_CUTOFF * h / np.pi, 0.5))
    velocity = signal.filtfilt(b, a, record.velocity)
    alpha = np.gradient(velocity, h)
    X = np.column_stack([alpha, velocity, signal.filtfilt(b, a, record.sign)])
    torque = signal.filtfilt(b, a, record.drive)
    edge = min(len(torque) // 10, round(1.0 / (RIGID_CUTOFF * h)))  # filter's ends
    coef = np.linalg.lstsq(X[edge : -edge or None], torque[edge : -edge or None], rcond=None)[0]
    return max(float(coef[0]) - record.J_m, 1e-2 * record.J_m)


def rigid_fit(encoder: EncoderRecord, motor: MotorRecord | None) -> ParameterFit:
    """The rigid drive fitted: ``J_load`` (kg·m²), then ``D_m``, ``f_c`` when not given
    and the load torque when modelled, with standard errors
    (:func:`~arcosim.identification.fit.encoder_fit.refine`, n = 0).

    Parameters
    ----------
    encoder : EncoderRecord
        The current → encoder record.
    motor : MotorRecord or None
        The same log's τ̂_reac record, for the reported τ̂ residual (N·m).

    Returns
    -------
    ParameterFit
        As :func:`~arcosim.identification.fit.encoder_fit.refine` gives it, with no modes.
    """
    J_load = rigid_start(encoder)
    start = np.array([J_load])
    note = "rigid drive (no mode in the band): J_load from the low-frequency torque balance"
    first = ParameterFit([RIGID_LOAD], start, np.zeros(1), start, note, 0.0, 0.0, 1, 0)
    first.extra.update(modes_rad_s=[], damping_ratios=[], singular_values=[])
    result = refine(encoder, None, first, 0)
    if motor is not None and motor.velocity is not None:
        residual = rigid_predict(motor, float(result.values[0])) - motor.tau_hat
        result.rms_residual = float(np.sqrt(np.mean(residual**2)))
        result.rms_data = float(np.sqrt(np.mean(motor.tau_hat**2)))
    return result
