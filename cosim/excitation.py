"""Current commands (A) for the scenarios, sampled at the communication steps.

Every function takes the step times ``t`` (s, shape ``(N,)``) and returns the
current held over each step (shape ``(N,)``).
"""

from __future__ import annotations

import numpy as np


def raised_cosine_window(
    t: np.ndarray, duration: float, ramp: float, derivative: int = 0
) -> np.ndarray:
    """Window that rises over ``ramp`` s as a raised cosine, holds 1, and falls over the
    last ``ramp`` s of ``duration``; 0 outside. ``derivative`` = 1 or 2 gives its
    first or second time derivative (1/s, 1/s²)."""
    t = np.asarray(t, dtype=float)
    k = np.pi / ramp
    out = np.zeros_like(t) if derivative else np.ones_like(t)
    for part, tau, sign in ((t < ramp, t, 1.0), (t > duration - ramp, duration - t, -1.0)):
        x = tau[part]
        if derivative == 0:
            out[part] = 0.5 - 0.5 * np.cos(k * x)
        elif derivative == 1:
            out[part] = sign * 0.5 * k * np.sin(k * x)
        else:
            out[part] = 0.5 * k * k * np.cos(k * x)
    out[(t < 0) | (t > duration)] = 0.0
    return out


def rigid_maneuver(
    t: np.ndarray,
    amplitude: float = 3.0,
    frequency: float = 2.1,
    periods: int = 8,
    ramp_periods: int = 3,
) -> np.ndarray:
    """Back-and-forth maneuver far below the first mode, without drift or ringing.

    The motion is ``p(t) = w(t) sin(ω t)`` with ``w`` a raised-cosine window of
    ``ramp_periods`` periods each side, and the current is proportional to its
    acceleration, ``i = −(amplitude / ω²) p̈``: p and ṗ vanish at both ends, so the
    current's first and second integrals vanish too and the chain swings about its
    start and comes back to rest there (a windowed cosine current would leave it
    several radians away). The smooth window keeps energy away from the resonances
    (shared/METHOD.md); ω defaults to about an eighth of the bench's first mode.

    The amplitude must be well above the current that overcomes the motor's
    Coulomb friction (f_c / k_t ≈ 0.05 A on the bench): the motor sticks at every
    reversal while the spring torque crosses the ±f_c band, the reaction torque
    is hidden then, and the double integral of mode 1 turns that into drift. On
    the bench 0.5 A gave k̂ 90 % low, 1 A 2–8 %, 2 A 1.3–3.5 % and 3 A (the
    default) 0.8–1.0 % (ideal to realistic sensors).

    Args:
        t: step times (s).
        amplitude: peak current (A), reached in the middle part.
        frequency: maneuver frequency ω (rad/s).
        periods: total length in periods (ramps included).
        ramp_periods: length of each ramp in periods.
    """
    period = 2 * np.pi / frequency
    duration, ramp = periods * period, ramp_periods * period
    w = raised_cosine_window(t, duration, ramp)
    w1 = raised_cosine_window(t, duration, ramp, derivative=1)
    w2 = raised_cosine_window(t, duration, ramp, derivative=2)
    s, c = np.sin(frequency * t), np.cos(frequency * t)
    return amplitude * (w * s - (2.0 / frequency) * w1 * c - w2 * s / frequency**2)


def multisine(
    t: np.ndarray, amplitude: float, frequencies: np.ndarray, seed: int = 0
) -> np.ndarray:
    """Sum of sines at ``frequencies`` (rad/s), random phases, scaled to peak ``amplitude`` (A)."""
    phases = np.random.default_rng(seed).uniform(0, 2 * np.pi, len(frequencies))
    signal = np.sum(np.sin(np.outer(t, frequencies) + phases), axis=1)
    return amplitude * signal / max(np.max(np.abs(signal)), 1e-300)


def chirp(t: np.ndarray, amplitude: float, w0: float, w1: float, duration: float) -> np.ndarray:
    """Linear chirp from ``w0`` to ``w1`` rad/s over ``duration`` s (A)."""
    rate = (w1 - w0) / duration
    return amplitude * np.sin(w0 * t + 0.5 * rate * t * t) * (t <= duration)


def filtered_random(t: np.ndarray, amplitude: float, cutoff: float, seed: int = 0) -> np.ndarray:
    """White noise through a 4th-order low-pass at ``cutoff`` (rad/s), rms ``amplitude`` (A)."""
    from scipy.signal import butter, sosfiltfilt

    h = float(np.median(np.diff(t))) if len(t) > 1 else 1e-3
    noise = np.random.default_rng(seed).normal(size=len(t))
    sos = butter(4, cutoff, fs=2 * np.pi / h, output="sos")
    signal = sosfiltfilt(sos, noise)
    return amplitude * signal / max(np.sqrt(np.mean(signal**2)), 1e-300)
