"""The zero-phase low-pass filter of the offline records (the motor's smoothed velocity,
:func:`~arcosim.identification.records.record.smooth_velocity`, and what it leaves in τ̂,
:func:`~arcosim.identification.checks.noise_floor.smoothing_error`)."""

from __future__ import annotations

import numpy as np
from scipy import signal


def low_passed(x: np.ndarray, h: float, cutoff: float) -> np.ndarray:
    """``x`` (any unit, shape ``(N,)``, step ``h`` in s) low-passed at ``cutoff`` (rad/s)
    forward and backward (2nd-order Butterworth each way: no lag, 4th-order roll-off);
    ``x`` itself when the cutoff is at or above the Nyquist rate or the record is too
    short to filter (12 samples or fewer).

    Examples
    --------
    >>> t = np.arange(2000) * 1e-3
    >>> slow = low_passed(np.sin(10 * t) + np.sin(2000 * t), 1e-3, 100.0)
    >>> bool(np.abs(slow - np.sin(10 * t))[200:-200].max() < 0.01)
    True
    """
    nyquist = np.pi / h
    if cutoff >= nyquist or len(x) <= 12:
        return x
    b, a = signal.butter(2, cutoff / nyquist)
    return signal.filtfilt(b, a, x)
