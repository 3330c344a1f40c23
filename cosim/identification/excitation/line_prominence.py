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

The same fit tells where lines are missing. The Hann window merges lines under two bins
(4π/T, its main lobe) apart into one peak, and the fit then puts one line where two or
more were played. What it leaves at that peak is a line's worth of signal: the residual's
periodogram stands there over its own noise level, at a played line's amplitude.
:func:`unresolved_lines` names those places, so a count of lines told apart is reported
as a least count where the record is too short to tell every line from its neighbour.
"""

from __future__ import annotations

import numpy as np

from arcosim.identification.excitation.periodic import detection_threshold, noise_level


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


def unresolved_lines(residual: np.ndarray, h: float, lines: np.ndarray, least: float) -> np.ndarray:
    """Where the lines fitted leave a line of the signal unexplained: lines the Hann
    window merged with a neighbour.

    A bin of the residual's Hann periodogram counts when it is a peak that stands over
    the residual's own noise level by the χ² threshold
    (:func:`~arcosim.identification.excitation.periodic.detection_threshold`), lies
    within the window's main lobe (two bins) of a line fitted (where a merged line
    hides) and has at least the amplitude ``least`` (a played line's; what a drive adds
    lies beneath it).

    Parameters
    ----------
    residual : ndarray
        The signal less the fitted lines, shape ``(N,)``, step ``h`` (s).
    h : float
        Its sample step (s).
    lines : ndarray
        The lines fitted (rad/s), shape ``(L,)``.
    least : float
        The least amplitude of a played line (the signal's unit).

    Returns
    -------
    ndarray
        Frequencies (rad/s) of the residual's peaks that are lines, ascending; empty
        when every line played was told apart.

    Examples
    --------
    Two lines 1.5 bins apart in 20 s (a bin 0.314 rad/s), fitted as one:

    >>> t = np.arange(2000) * 1e-2
    >>> x = np.sin(5.0 * t) + np.sin(5.47 * t + 1.0)
    >>> rest = x - np.sin(5.2 * t + 0.4) * 1.6
    >>> np.round(unresolved_lines(rest, 1e-2, np.array([5.2]), 0.5), 2)
    array([5.34])
    >>> unresolved_lines(np.sin(5.2 * t) * 1e-4, 1e-2, np.array([5.2]), 0.5)
    array([], dtype=float64)
    """
    n = len(residual)
    power = np.abs(np.fft.rfft(residual * np.hanning(n))) ** 2
    level = np.concatenate([[np.inf], noise_level(power[1:])])
    q = detection_threshold(len(power) - 1)
    peak = np.zeros(len(power), dtype=bool)
    peak[1:-1] = (power[1:-1] > power[:-2]) & (power[1:-1] >= power[2:])
    resolution = 2.0 * np.pi / (n * h)
    frequency = np.arange(len(power)) * resolution
    near = np.zeros(len(power), dtype=bool)
    for w in np.asarray(lines, dtype=float):  # each line's main lobe, without an N × L table
        near[max(int(np.ceil(w / resolution - 2.0)), 0) : int(w / resolution + 2.0) + 1] = True
    line = peak & near & (power > q * level) & (noise_amplitude(power, n) >= least)
    return frequency[line]
