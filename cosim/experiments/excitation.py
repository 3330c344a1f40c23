"""Current commands (A) sampled at the communication steps, for scripts and scenarios.

Thin array wrappers over :mod:`flexchain.excitation`, the standard-library
implementation that the ExcitationSource FMU runs too. Every function takes the
step times ``t`` (s, shape ``(N,)``) and returns the current held over each step
(shape ``(N,)``).
"""

from __future__ import annotations

import numpy as np

from arcosim.fmu.flexchain import excitation as _signals


def rigid_maneuver(
    t: np.ndarray,
    amplitude: float = 3.0,
    frequency: float = 2.1,
    periods: int = 8,
    ramp_periods: int = 3,
) -> np.ndarray:
    """See :func:`flexchain.excitation.rigid_maneuver` (drift-free, far below the modes)."""
    return np.array(
        [_signals.rigid_maneuver(x, amplitude, frequency, periods, ramp_periods) for x in t]
    )


def multisine(
    t: np.ndarray, amplitude: float, frequencies: np.ndarray, seed: int = 0
) -> np.ndarray:
    """Sines at ``frequencies`` (rad/s), random phases from ``seed``, peak ≤ ``amplitude`` (A)."""
    frequencies = [float(w) for w in frequencies]
    phases = _signals.multisine_phases(len(frequencies), seed)
    return np.array([_signals.multisine(x, amplitude, frequencies, phases) for x in t])


def chirp(t: np.ndarray, amplitude: float, w0: float, w1: float, duration: float) -> np.ndarray:
    """Linear chirp from ``w0`` to ``w1`` rad/s over ``duration`` s (A)."""
    return np.array([_signals.chirp(x, amplitude, w0, w1, duration) for x in t])


def filtered_random(t: np.ndarray, amplitude: float, cutoff: float, seed: int = 0) -> np.ndarray:
    """White noise through a 4th-order Butterworth at ``cutoff`` (rad/s), rms ``amplitude`` (A)."""
    noise = _signals.FilteredNoise(amplitude, cutoff, seed)
    steps = np.diff(t, prepend=t[0] - (t[1] - t[0] if len(t) > 1 else 1e-3))
    return np.array([noise.next(float(h)) for h in steps])
