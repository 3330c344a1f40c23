"""Which of the lines a periodogram found are lines: the prominence test again, on the
amplitudes a joint fit gives (offline).

:mod:`arcosim.identification.excitation.spectrum` finds a multi-sine's lines as the Hann
periodogram's peaks that stand the χ² threshold above its noise level and above the
leakage of every stronger line, then refines them by least squares. One source of a false peak
stays: removing the signal's linear trend also removes its lines' projection on a
constant and a ramp, and leaves that projection, sign turned, in the signal. A ramp's
Hann spectrum peaks one to two bins above 0, where the periodogram then finds a weak
"line" (0.48 rad/s in a 20 s record of 40 lines 3–150 rad/s, 1 % of their amplitude),
which fed the torque balance and the record-length check false warnings. Once the lines
are fitted that remnant is known: :func:`prominent_lines` asks each line to pass the
same threshold over the noise and it.
"""

from __future__ import annotations

import numpy as np


def noise_amplitude(floor: float | np.ndarray, n: int) -> float | np.ndarray:
    """The amplitude (the signal's unit) whose Hann periodogram peak, (a·Σw/2)², is the
    periodogram's level ``floor`` (its noise level), the record ``n`` samples long: that
    level in a line's unit.

    Parameters
    ----------
    floor : float or ndarray
        The Hann-windowed periodogram's noise level (the signal's unit squared), any
        shape.
    n : int
        Samples in the record (a count).

    Returns
    -------
    float or ndarray
        The amplitude (the signal's unit), the shape of ``floor``.

    Examples
    --------
    >>> noise = np.random.default_rng(0).standard_normal(20000)
    >>> power = np.abs(np.fft.rfft(noise * np.hanning(20000))) ** 2
    >>> round(noise_amplitude(float(np.median(power[1:])), 20000), 4)   # unit white noise
    0.0142
    """
    amplitude = 2.0 * np.sqrt(floor) / np.sum(np.hanning(n))
    return float(amplitude) if np.ndim(amplitude) == 0 else amplitude


def prominent_lines(
    x: np.ndarray, h: float, lines: np.ndarray, noise: float | np.ndarray, prominence: float
) -> np.ndarray:
    """Which refined lines pass the periodogram's test again, on their fitted amplitudes:
    ``prominence`` times (in power) above the noise and the detrend's remnant.

    The remnant each line sees is the projection of all the other fitted lines on a
    constant and a ramp; a line whose fitted amplitude a has a² under ``prominence`` ·
    (a_noise² + a_rem²), a_rem that remnant's amplitude at its frequency, is not told
    from them (the rule the periodogram's peaks pass against the stronger lines'
    leakage, :func:`~arcosim.identification.excitation.spectrum.spectral_lines`).

    Parameters
    ----------
    x : ndarray
        The signal the lines were fitted on (trend removed), shape ``(N,)``.
    h : float
        Its sample step (s).
    lines : ndarray
        The refined lines (rad/s), shape ``(L,)``.
    noise : float or ndarray
        The noise level in a line's amplitude (the signal's unit, :func:`noise_amplitude`),
        one for all or one per line, shape ``(L,)``.
    prominence : float
        The power ratio a line must stand above the noise and the remnant
        (dimensionless; the χ² threshold,
        :func:`~arcosim.identification.excitation.periodic.detection_threshold`).

    Returns
    -------
    ndarray
        Boolean, shape ``(L,)``: the lines that count.

    Examples
    --------
    A linear detrend of a multi-sine from 3 rad/s leaves a ramp that the periodogram
    reads as a line near 0.5 rad/s; it does not pass:

    >>> t = np.arange(20000) * 1e-3
    >>> lines = np.geomspace(3.0, 150.0, 40)
    >>> x = np.sin(np.outer(t, lines) + np.arange(40.0)).sum(axis=1) * 0.075
    >>> x = x - np.polyval(np.polyfit(t, x, 1), t)
    >>> prominent_lines(x, 1e-3, np.concatenate([[0.48], lines]), 7e-5, 30.0)[:3]
    array([False,  True,  True])
    """
    t = np.arange(len(x)) * h
    t = t - t.mean()
    phase = np.outer(t, lines)
    cos, sin = np.cos(phase), np.sin(phase)
    coef = np.linalg.lstsq(np.hstack([cos, sin]), x, rcond=None)[0]
    c, s = coef[: len(lines)], coef[len(lines) :]
    trend = np.column_stack([np.ones_like(t), t / max(float(np.abs(t).max()), 1e-300)])
    basis = np.linalg.qr(trend)[0]
    each = basis.T @ (cos * c + sin * s)  # each line's projection on the constant and ramp
    keep = np.zeros(len(lines), dtype=bool)
    noise = np.broadcast_to(np.asarray(noise, dtype=float), (len(lines),))
    for i in range(len(lines)):
        remnant = basis @ (each.sum(axis=1) - each[:, i])
        pair = np.column_stack([cos[:, i], sin[:, i]])
        a_rem = float(np.hypot(*np.linalg.lstsq(pair, remnant, rcond=None)[0]))
        keep[i] = np.hypot(c[i], s[i]) ** 2 >= prominence * (noise[i] ** 2 + a_rem**2)
    return keep
