"""The Hann-windowed periodogram, its noise level, and the bins that stand over it.

The one test that says a bin holds a line
(:mod:`arcosim.identification.excitation.spectrum`): its power over the periodogram's
noise level (the local lower quartile over ln(4/3),
:func:`~arcosim.identification.excitation.periodic.noise_level`) by the χ² threshold
(:func:`~arcosim.identification.excitation.periodic.detection_threshold`); in what
fitted lines leave, a bin that passes it at a played line's amplitude holds a line's
worth of signal (:func:`line_worth`).
"""

from __future__ import annotations

import numpy as np

from arcosim.identification.excitation.line_prominence import noise_amplitude
from arcosim.identification.excitation.periodic import detection_threshold, noise_level


def hann_power(x: np.ndarray) -> np.ndarray:
    """The Hann-windowed periodogram of ``x`` (shape ``(N,)``; its unit squared), shape
    ``(N//2 + 1,)``: bin k at k·2π/(N·h) rad/s for a step h.

    Examples
    --------
    >>> x = np.sin(2 * np.pi * 10 * np.arange(1000) / 1000)   # 10 periods in 1000 samples
    >>> int(np.argmax(hann_power(x)))
    10
    """
    return np.abs(np.fft.rfft(x * np.hanning(len(x)))) ** 2


def hann_peaks(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """The Hann periodogram of ``x`` (shape ``(N,)``), its noise level at each bin (its
    local lower quartile over ln(4/3),
    :func:`~arcosim.identification.excitation.periodic.noise_level`; infinite at 0), the
    χ² threshold q over its bins and which bins are its local peaks (boolean, shape
    ``(N//2 + 1,)``)."""
    power = hann_power(x)
    level = np.concatenate([[np.inf], noise_level(power[1:])])
    q = detection_threshold(len(power) - 1)
    peak = np.zeros(len(power), dtype=bool)
    peak[1:-1] = (power[1:-1] > power[:-2]) & (power[1:-1] >= power[2:])
    return power, level, q, peak


def line_worth(
    peaks: tuple[np.ndarray, np.ndarray, float, np.ndarray], n: int, least: float
) -> np.ndarray:
    """Which bins of a residual's Hann periodogram hold a played line's worth of signal:
    over the residual's own noise level by the χ² threshold and of at least the amplitude
    ``least`` (the signal's unit).

    Parameters
    ----------
    peaks : tuple
        The residual's :func:`hann_peaks` (its periodogram, noise level, threshold and
        peaks), the residual being the signal less the fitted lines.
    n : int
        Samples in the residual (a count).
    least : float
        The least amplitude of a played line (the signal's unit).

    Returns
    -------
    ndarray
        Boolean, shape ``(N//2 + 1,)``: bin k at k·2π/(N·h) rad/s.

    Examples
    --------
    >>> t = np.arange(2000) * 1e-2
    >>> np.flatnonzero(line_worth(hann_peaks(np.sin(2 * np.pi * 0.5 * t)), 2000, 0.5))
    array([ 9, 10, 11])
    """
    power, level, q, _ = peaks
    return (power > q * level) & (noise_amplitude(power, n) >= least)
