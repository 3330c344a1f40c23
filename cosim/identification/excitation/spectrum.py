"""What a drive log's excitation is: lines, harmonics of one period, or broadband (offline).

:func:`excitation_spectrum` reads a command or a measured current (any unit, a constant
step) and says what was played, for the log's check and the fits' decisions
(:mod:`arcosim.identification.checks.log_decision`) and for the measured frequency response
(:mod:`arcosim.identification.checks.frf`). One test decides what is a line: a bin whose
power stands over the noise level (the mean power of a noise bin) by the χ² threshold
q = ln(K / 0.5) over the K bins tested, so that noise alone passes on half a bin of the
band on average (:func:`~arcosim.identification.excitation.periodic.detection_threshold`).

- **periodic, whole periods** (a Schroeder or random-phase multi-sine played period
  after period, a square wave, when the record holds M ≥ 2 whole periods): the period
  from the greatest common divisor of the strongest bins on the record's DFT grid, the
  noise level from the bins between the harmonics, the lines the harmonics above it
  (:mod:`arcosim.identification.excitation.periodic`); the fundamental is the greatest
  common divisor of the lines played;
- **lines** (a multi-sine whose lines are not harmonics of the record's period): the
  peaks of the Hann-windowed periodogram above the threshold *and* above the leakage of
  every stronger line (the window's sidelobe envelope, :func:`leakage_envelope`), so an
  off-grid line counts once and not as the dozen sidelobes its leakage leaves; each
  line's frequency then refined by a least-squares fit of a sine at off-grid frequencies
  (:func:`refine_lines`), and a line kept only if its fitted amplitude passes the same
  threshold over the noise and the linear detrend's remnant
  (:mod:`arcosim.identification.excitation.line_prominence`: that remnant, a ramp, reads as
  a weak line one to two bins above 0); lines that sit on whole multiples of one
  fundamental whose first harmonics are present (a periodic reference over a record of
  no whole number of periods) read as **periodic**
  (:func:`~arcosim.identification.excitation.harmonics.harmonic_fundamental`); where
  the fitted lines leave a line's worth of signal, the window merged lines closer than
  two bins (:func:`unresolved_lines`): a least-squares search tells them apart again
  (:mod:`~arcosim.identification.excitation.merged_lines`), and where it cannot (lines
  under the Rayleigh limit, one bin, apart) the count is a least count, with where more
  lines lie;
- in both, the lines the drive adds beneath the played ones (friction's and the current
  loop's harmonics, in a measured current) are not played lines (:func:`played_lines`);
- **broadband** (PRBS, noise, steps): lines that carry less than
  :data:`LINE_SHARE` of the signal's power; the usable band is where the Welch spectrum
  stays within :data:`BROADBAND_DROP` of its peak (:func:`broadband_band`).

Each kind gives the lowest frequency the excitation carries (the record-length and
torque-balance checks read it) and its top (the band checks read it).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import signal as sp_signal

from arcosim.identification.excitation.harmonics import (
    harmonic_fundamental,
    on_harmonics,
)
from arcosim.identification.excitation.line_prominence import noise_amplitude, prominent_lines
from arcosim.identification.excitation.merged_lines import DECIMATE_MARGIN, resolve_merged_lines
from arcosim.identification.excitation.periodic import (
    harmonic_lines,
    on_grid,
    whole_periods,
)
from arcosim.identification.excitation.periodogram import hann_peaks, line_worth

#: Share of the signal's power (dimensionless, 0 … 1) the lines must carry for the
#: excitation to count as lines; below it, broadband.
LINE_SHARE = 0.8
#: More lines than this (a count) are read as broadband (a line fit would be slow and
#: no multi-sine plays that many).
MAX_LINES = 2000
#: Bins (a count) either side of a line its leakage is counted over: beyond, the Hann
#: envelope is under 1e-15 of the line.
LEAKAGE_REACH = 256
#: Lines are refined by least squares (:func:`refine_lines`) up to this many (a count).
REFINE_LIMIT = 120
#: Broadband: the usable band is where the Welch spectrum stays above this fraction of
#: its peak (dimensionless; 0.1: −10 dB).
BROADBAND_DROP = 0.1
#: Least periods (a count) a line must hold in the record: under one it is a trend, not
#: a line (a line of one to three periods is kept, and the record-length check warns of
#: it).
LEAST_LINE_PERIODS = 1.0
#: The lines a drive adds lie beneath the played ones by at least this ratio of
#: amplitudes (dimensionless; 2: 6 dB). A designed multi-sine's lines, flat or shaped
#: smoothly over the band, differ from their neighbours in amplitude far less (40
#: log-spaced lines with amplitudes ∝ ω: 10 %); a square wave's first two harmonics by
#: 3, which :data:`DISTORTION_SHARE` keeps together.
DISTORTION_GAP = 2.0
#: The lines beneath such a gap are the drive's own when they carry at most this share
#: of the lines' power (dimensionless; 0.05: 13 dB under the played lines): what a
#: linear chain's fit leaves as distortion, not what an excitation plays (a square
#: wave's harmonics above its fundamental carry 19 %).
DISTORTION_SHARE = 0.05


@dataclass(frozen=True)
class ExcitationSpectrum:
    """What a signal's spectrum shows (see :func:`excitation_spectrum`).

    Attributes
    ----------
    kind : str
        ``"lines"`` (a multi-sine), ``"periodic"`` (harmonics of one fundamental),
        ``"broadband"`` or ``"none"`` (no excitation found).
    lines : ndarray
        The lines played (rad/s), ascending, shape ``(L,)``: the multi-sine's lines, or
        the harmonics present; empty for broadband.
    amplitudes : ndarray
        Each line's amplitude (the signal's unit), shape ``(L,)``.
    band : tuple of float
        The lowest and highest frequency the excitation carries (rad/s).
    fundamental : float
        The fundamental (rad/s) of a periodic excitation; 0 otherwise.
    line_share : float
        Share of the signal's power in the lines (dimensionless, 0 … 1).
    resolution : float
        The record's frequency grid 2π/T (rad/s).
    periods : int
        Whole periods the record holds (a count); 0 when it is not read as whole
        periods.
    unresolved : ndarray
        Where more lines lie than were told apart (rad/s), shape ``(U,)``: lines that
        the Hann window merged (under two bins, 4π/T, apart), found in what the fitted
        lines leave (:func:`unresolved_lines`), and that the least-squares search of
        :mod:`~arcosim.identification.excitation.merged_lines` did not tell apart;
        ``lines`` then holds a least count. Empty when every line was told apart.
    """

    kind: str
    lines: np.ndarray = field(default_factory=lambda: np.empty(0))
    amplitudes: np.ndarray = field(default_factory=lambda: np.empty(0))
    band: tuple[float, float] = (0.0, 0.0)
    fundamental: float = 0.0
    line_share: float = 0.0
    resolution: float = 0.0
    periods: int = 0
    unresolved: np.ndarray = field(default_factory=lambda: np.empty(0))

    @property
    def lowest(self) -> float | None:
        """The lowest frequency excited (rad/s), or None without excitation."""
        return self.band[0] if self.kind != "none" else None

    @property
    def highest(self) -> float | None:
        """The highest frequency excited (rad/s), or None without excitation."""
        return self.band[1] if self.kind != "none" else None

    def text(self) -> str:
        """One line for the user.

        Examples
        --------
        >>> ExcitationSpectrum("periodic", np.array([1.0, 3.0, 5.0]), np.ones(3), (1.0, 5.0),
        ...                    1.0).text()
        'periodic: 3 lines on harmonics of 1 rad/s (period 6.28 s), 1 … 5 rad/s'
        >>> lines = np.arange(11.0, 251.0) * 2 * np.pi
        >>> ExcitationSpectrum("periodic", lines, np.ones(240), (lines[0], lines[-1]),
        ...                    2 * np.pi, periods=20).text()[:72]
        'periodic: 240 lines on harmonics of 6.283 rad/s (period 1 s, 20 whole pe'
        """
        low, high = self.band
        span = f"{low:.3g} … {high:.4g} rad/s"
        if self.kind == "lines":
            return f"multi-sine: {len(self.lines)} lines, {span}{self._unresolved_text()}"
        if self.kind == "periodic":
            period = 2 * np.pi / self.fundamental
            whole = f", {self.periods} whole periods in the record" if self.periods else ""
            return (
                f"periodic: {len(self.lines)} lines on harmonics of {self.fundamental:.4g} "
                f"rad/s (period {period:.3g} s{whole}), {span}"
            )
        if self.kind == "broadband":
            return f"broadband: {span} (the Welch spectrum within 10 dB of its peak)"
        return "no excitation found"

    def _unresolved_text(self) -> str:
        """The clause on lines not told apart, or ``""``."""
        if not len(self.unresolved):
            return ""
        near = ", ".join(f"{w:.3g}" for w in self.unresolved)
        record = 2.0 * np.pi / self.resolution
        return (
            f"; more lines near {near} rad/s, not told apart (the window merges lines "
            f"under two bins, {2 * self.resolution:.3g} rad/s, apart, and a {record:.3g} s "
            f"record parts them only above one bin, {self.resolution:.3g} rad/s: a longer "
            "record tells them apart)"
        )


def excitation_spectrum(x: np.ndarray, h: float) -> ExcitationSpectrum:
    """What excitation a signal carries: lines, harmonics of one period, or broadband.

    A record of whole periods (:func:`~arcosim.identification.excitation.periodic.whole_periods`)
    is read on its harmonics (:func:`~arcosim.identification.excitation.periodic.harmonic_lines`),
    any other by the Hann periodogram's peaks (:func:`spectral_lines`); in both, a bin
    counts as a line when it stands over the noise level by the χ² threshold that lets
    :data:`~arcosim.identification.excitation.periodic.FALSE_LINES` noise bins through
    over the band, and the lines played are told from the drive's own lines beneath them
    (:func:`played_lines`).

    Parameters
    ----------
    x : ndarray
        The signal (a current or a command, any unit), shape ``(N,)``, step ``h``.
    h : float
        Sample step (s).

    Returns
    -------
    ExcitationSpectrum
        The kind, the lines (rad/s) with their amplitudes, the band the excitation
        carries (rad/s) and, for a periodic excitation, its fundamental.

    Examples
    --------
    A multi-sine of 40 lines off the record's grid counts as lines, not as their leakage;
    in 20 s the lines under about 6 rad/s lie one to two bins apart and merge in the
    window, and the search of :mod:`~arcosim.identification.excitation.merged_lines`
    tells them apart again:

    >>> t = np.arange(20001) * 1e-3
    >>> lines = np.geomspace(3.0, 150.0, 40)
    >>> phases = np.random.default_rng(1).uniform(0, 2 * np.pi, 40)
    >>> current = np.sin(np.outer(t, lines) + phases).sum(axis=1) * 0.075
    >>> found = excitation_spectrum(current, 1e-3)
    >>> found.kind, len(found.lines), round(found.band[1], 1)
    ('lines', 40, 150.0)

    In 10 s the lowest lie half a bin apart, under the Rayleigh limit: fewer are told
    apart, and what the fitted lines leave says where more lie:

    >>> found = excitation_spectrum(current[:10001], 1e-3)
    >>> len(found.lines) < 40, found.text()[:47]
    (True, 'multi-sine: 29 lines, 4.07 … 150 rad/s; more li')

    The same lines moved onto the record's grid: each in its own bin, all 40:

    >>> grid = 2 * np.pi / 20.001
    >>> current = np.sin(np.outer(t, np.rint(lines / grid) * grid) + phases).sum(axis=1) * 0.075
    >>> current += 0.005 * np.random.default_rng(2).standard_normal(len(t))
    >>> len(excitation_spectrum(current, 1e-3).lines)
    40
    """
    x = np.asarray(x, dtype=float)
    if len(x) < 16 or not np.all(np.isfinite(x)):
        return ExcitationSpectrum("none")
    resolution = 2.0 * np.pi / (len(x) * h)
    centred = x - x.mean()
    periodic = _periodic(centred, h)
    if periodic is not None:
        return periodic
    t = np.arange(len(x)) * h
    x = x - np.polyval(np.polyfit(t, x, 1), t)
    if not np.any(x):
        return ExcitationSpectrum("none", resolution=resolution)
    lines, amplitudes, share, unresolved = spectral_lines(x, h)
    if len(lines) and share >= LINE_SHARE and on_grid(lines, resolution):
        # on the grid, no window: each line in its bin, lines a bin apart apart
        bins, amplitudes, _ = harmonic_lines(centred, 1)
        played = played_lines(amplitudes)
        lines, amplitudes = bins[played] * resolution, amplitudes[played]
        unresolved = np.empty(0)
    if len(lines) and share >= LINE_SHARE:
        fundamental = harmonic_fundamental(lines, resolution)
        kind = "periodic" if fundamental else "lines"
        band = (float(lines[0]), float(lines[-1]))
        unresolved = unresolved if kind == "lines" else np.empty(0)
        return ExcitationSpectrum(
            kind, lines, amplitudes, band, fundamental, share, resolution, 0, unresolved
        )
    band = broadband_band(x, h)
    if band is None:
        return ExcitationSpectrum("none", line_share=share, resolution=resolution)
    return ExcitationSpectrum("broadband", band=band, line_share=share, resolution=resolution)


def _periodic(x: np.ndarray, h: float) -> ExcitationSpectrum | None:
    """The spectrum of a record of whole periods (``x`` mean removed, shape ``(N,)``,
    step ``h`` s), its lines those played; None when it does not hold whole periods
    or its harmonics carry under :data:`LINE_SHARE` of its power."""
    periods = whole_periods(x)
    if not periods:
        return None
    harmonics, amplitudes, share = harmonic_lines(x, periods)
    if len(harmonics) == 0 or share < LINE_SHARE:
        return None
    played = played_lines(amplitudes)
    harmonics, amplitudes = harmonics[played], amplitudes[played]
    per_period = 2.0 * np.pi * periods / (len(x) * h)  # the first harmonic (rad/s)
    lines = harmonics * per_period
    fundamental = float(np.gcd.reduce(harmonics)) * per_period
    band = (float(lines[0]), float(lines[-1]))
    resolution = 2.0 * np.pi / (len(x) * h)
    return ExcitationSpectrum(
        "periodic", lines, amplitudes, band, fundamental, share, resolution, periods
    )


def played_lines(amplitudes: np.ndarray) -> np.ndarray:
    """Which lines the excitation plays, among lines that all stand above the noise.

    A drive adds lines of its own in step with what it is played: friction's and the
    current loop's harmonics and intermodulation, in the current as in the motion. They
    are lines too, above the noise, but beneath the played ones: a multi-sine plays its
    lines at one designed level (flat, or shaped smoothly across the band), and a log
    fit for a linear chain has what the drive adds well below it (else no linear model
    describes it). The lines sorted by amplitude part at their widest ratio between
    neighbours when it spans at least :data:`DISTORTION_GAP` and the lines beneath carry
    at most :data:`DISTORTION_SHARE` of the lines' power; otherwise every line is played
    (a square wave's harmonics, falling as 1/k, carry 19 % of its power above the
    fundamental: all played).

    Parameters
    ----------
    amplitudes : ndarray
        The lines' amplitudes (any unit), shape ``(L,)``.

    Returns
    -------
    ndarray
        Boolean, shape ``(L,)``: the lines played.

    Examples
    --------
    240 lines near 0.85 A over 1000 harmonics of friction under 0.15 A (the motor
    bench's current):

    >>> rng = np.random.default_rng(0)
    >>> a = np.concatenate([rng.uniform(0.77, 0.93, 240), rng.uniform(0.001, 0.142, 1000)])
    >>> int(played_lines(a).sum())
    240
    >>> int(played_lines(1.0 / np.arange(1, 40, 2)).sum())   # a square wave's
    20
    """
    a = np.asarray(amplitudes, dtype=float)
    played = np.ones(len(a), dtype=bool)
    if len(a) < 2:
        return played
    order = np.argsort(-a)
    sorted_a = np.maximum(a[order], 1e-300)
    power = sorted_a**2
    beneath = (power.sum() - np.cumsum(power))[:-1] / power.sum()  # below each split
    ratio = sorted_a[:-1] / sorted_a[1:]
    allowed = (beneath <= DISTORTION_SHARE) & (ratio >= DISTORTION_GAP)
    if not np.any(allowed):
        return played
    split = int(np.argmax(np.where(allowed, ratio, 0.0)))
    played[order[split + 1 :]] = False
    return played


def spectral_lines(x: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """The lines of a detrended signal, leakage-aware.

    Peaks of the Hann-windowed periodogram that stand over its noise level (its local
    lower quartile over ln(4/3)) by the χ² threshold
    (:func:`~arcosim.identification.excitation.periodic.detection_threshold`) and over
    the leakage of every stronger peak (:func:`leakage_envelope`); then, unless they
    are harmonics of one fundamental, their frequencies refined together by least
    squares (:func:`refine_lines`) on the signal decimated to the lines' band, each
    held to the same threshold on its fitted amplitude
    (:func:`~arcosim.identification.excitation.line_prominence.prominent_lines`), and
    the lines played kept (:func:`played_lines`); where the fit leaves a played line's
    worth of signal near a line, the window merged more lines there
    (:func:`unresolved_lines`), and the search of
    :func:`~arcosim.identification.excitation.merged_lines.resolve_merged_lines` tells
    them apart where the record can.

    Parameters
    ----------
    x : ndarray
        The signal, trend removed, shape ``(N,)``.
    h : float
        Sample step (s).

    Returns
    -------
    lines : ndarray
        Frequencies (rad/s), ascending, shape ``(L,)``.
    amplitudes : ndarray
        Amplitudes (the signal's unit), shape ``(L,)``.
    share : float
        Share of the signal's power in the lines (dimensionless).
    unresolved : ndarray
        Where more lines lie than were told apart (rad/s), shape ``(U,)``; empty when
        none, or when the lines were not refined.

    Examples
    --------
    >>> t = np.arange(4000) * 1e-3
    >>> x = np.sin(10.3 * t) + 0.5 * np.sin(40.1 * t)
    >>> lines, amplitudes, share, unresolved = spectral_lines(x, 1e-3)
    >>> np.round(lines, 2), np.round(amplitudes, 2), round(share, 2), len(unresolved)
    (array([10.29, 40.08]), array([1. , 0.5]), 1.0, 0)
    """
    n = len(x)
    bins, power, level, q = _peaks(x)
    if not len(bins):
        return np.empty(0), np.empty(0), 0.0, np.empty(0)
    # the lines' power: over each peak's main lobe (two bins either side), and every
    # bin above the threshold between the first and the last peak, so that lines a
    # window merges count whole (a step's 1/k decay from its one peak does not)
    near = np.zeros(len(power), dtype=bool)
    for d in range(-2, 3):
        near[np.clip(bins + d, 1, len(power) - 1)] = True
    inside = np.zeros(len(power), dtype=bool)
    inside[bins[0] : bins[-1] + 1] = True
    near |= inside & (power > q * level)
    share = float(power[near].sum() / max(power[1:].sum(), 1e-300))
    if share < LINE_SHARE or len(bins) > MAX_LINES:
        return np.empty(0), np.empty(0), share, np.empty(0)
    resolution = 2.0 * np.pi / (n * h)
    amplitude = 2.0 * np.sqrt(power[bins]) / np.sum(np.hanning(n))
    position = _interpolated(power, bins)
    keep = position >= LEAST_LINE_PERIODS  # under one period in the record: a trend
    if not np.any(keep):
        return np.empty(0), np.empty(0), share, np.empty(0)
    coarse = position[keep] * resolution
    amplitude = amplitude[keep]
    # a periodic reference's harmonics, all of them (in a position loop its current
    # shows the loop's resonance above them: they are played all the same)
    w0 = harmonic_fundamental(coarse, resolution, amplitude)
    if w0:
        on = on_harmonics(coarse, w0, resolution)
        return np.rint(coarse[on] / w0) * w0, amplitude[on], share, np.empty(0)
    played = played_lines(amplitude)
    coarse, amplitude = coarse[played], amplitude[played]
    if len(coarse) > REFINE_LIMIT:  # no multi-sine plays that many: not worth the fit
        return coarse, amplitude, share, np.empty(0)
    q_decimate = max(int(np.pi / (h * DECIMATE_MARGIN * coarse[-1])), 1)
    y = sp_signal.resample_poly(x, 1, q_decimate) if q_decimate > 1 else x
    lines, amplitudes, residual = refine_lines(y, q_decimate * h, coarse)
    at = np.clip(np.rint(lines / resolution).astype(int), 1, len(level) - 1)
    noise = noise_amplitude(level[at], n)
    prominent = prominent_lines(y, q_decimate * h, lines, noise, q)
    order = np.argsort(lines[prominent])
    lines, amplitudes = lines[prominent][order], amplitudes[prominent][order]
    if not len(lines):
        return lines, amplitudes, share, np.empty(0)
    least = float(amplitudes.min()) / DISTORTION_GAP  # a played line, not the drive's
    unresolved = unresolved_lines(residual, q_decimate * h, lines, least)
    if len(unresolved):
        told = resolve_merged_lines(y, q_decimate * h, lines, unresolved, least, resolution)
        if told is not None:
            return told[0], told[1], share, np.empty(0)
    return lines, amplitudes, share, unresolved


def _peaks(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Bins of the lines in ``x`` (shape ``(N,)``): peaks of the Hann periodogram whose
    power exceeds q times the noise level plus the leakage envelope of every stronger
    peak, q the χ² threshold over the periodogram's bins; with the periodogram, the
    noise level at each bin (its local lower quartile over ln(4/3),
    :func:`~arcosim.identification.excitation.periodic.noise_level`) and q."""
    power, level, q, peak = hann_peaks(x)
    candidates = np.flatnonzero(peak & (power > q * level))
    accepted: list[int] = []
    leak = np.zeros(len(power))
    reach = np.arange(-LEAKAGE_REACH, LEAKAGE_REACH + 1)
    envelope = leakage_envelope(reach)
    for j in candidates[np.argsort(-power[candidates])]:
        if power[j] <= q * (level[j] + leak[j]):
            continue
        accepted.append(int(j))
        near = (j + reach >= 0) & (j + reach < len(power))
        leak[j + reach[near]] += power[j] * envelope[near]
    return np.sort(np.array(accepted, dtype=int)), power, level, q


def unresolved_lines(residual: np.ndarray, h: float, lines: np.ndarray, least: float) -> np.ndarray:
    """Where the lines fitted leave a line of the signal unexplained: lines the Hann
    window merged with a neighbour.

    The fit puts one line where the window merged two or more, and what it leaves at
    that peak is a line's worth of signal. A bin of the residual's Hann periodogram
    counts when it is a peak that stands over the residual's own noise level by the χ²
    threshold (:func:`~arcosim.identification.excitation.periodogram.line_worth`, the
    test the lines found pass), lies within the window's main lobe (two bins) of a line
    fitted (where a merged line hides) and has at least the amplitude ``least`` (a
    played line's; what a drive adds lies beneath it).

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
    peaks = hann_peaks(residual)
    peak = peaks[3]
    resolution = 2.0 * np.pi / (n * h)
    frequency = np.arange(len(peak)) * resolution
    near = np.zeros(len(peak), dtype=bool)
    for w in np.asarray(lines, dtype=float):  # each line's main lobe, without an N × L table
        near[max(int(np.ceil(w / resolution - 2.0)), 0) : int(w / resolution + 2.0) + 1] = True
    return frequency[peak & near & line_worth(peaks, n, least)]


def leakage_envelope(distance: np.ndarray) -> np.ndarray:
    """Upper bound of the Hann window's leakage, relative to a line's peak bin, at
    ``distance`` bins from it (dimensionless power ratio; 1 within the main lobe).

    The Hann window's transform falls as sinc(d)/(1 − d²); over every offset of a line
    from the grid (scalloping up to 1.42 dB) its magnitude stays under 1/(π·d·(d² − 1))
    at d bins from the line, the line at most half a bin from its peak bin.

    Parameters
    ----------
    distance : ndarray
        Distance from the line's peak bin (bins), any shape.

    Returns
    -------
    ndarray
        The power ratio bound, same shape.

    Examples
    --------
    >>> np.round(leakage_envelope(np.array([0, 1, 3, 10])), 6)
    array([1.00e+00, 1.00e+00, 8.17e-04, 0.00e+00])
    """
    d = np.maximum(np.abs(np.asarray(distance, dtype=float)) - 0.5, 1.5)
    bound = (1.0 / (np.pi * d * (d**2 - 1.0))) ** 2 / 0.72  # 0.72: the worst scalloping
    return np.where(np.abs(distance) <= 1, 1.0, np.minimum(bound, 1.0))


def _interpolated(power: np.ndarray, bins: np.ndarray) -> np.ndarray:
    """Peak positions (fractional bins) by a parabola through the log power."""
    left, mid, right = (np.log(np.maximum(power[bins + d], 1e-300)) for d in (-1, 0, 1))
    curvature = left - 2 * mid + right
    shift = 0.5 * (left - right) / np.where(curvature == 0, -1.0, curvature)
    return bins + np.clip(shift, -0.5, 0.5)


def refine_lines(
    x: np.ndarray, h: float, lines: np.ndarray, sweeps: int = 4
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lines' frequencies refined by least squares at off-grid frequencies.

    Every line's sine and cosine amplitude and its frequency are fitted together by
    ``sweeps`` Gauss–Newton steps, each frequency held within half a bin (π/T) of its
    start (lines the window merged would otherwise wander).

    Parameters
    ----------
    x : ndarray
        The signal, trend removed, shape ``(N,)``, step ``h`` (s).
    h : float
        Sample step (s).
    lines : ndarray
        Starting frequencies (rad/s), shape ``(L,)``.
    sweeps : int
        Gauss–Newton steps (a count).

    Returns
    -------
    lines : ndarray
        Refined frequencies (rad/s), in the order given, shape ``(L,)``.
    amplitudes : ndarray
        Their amplitudes (the signal's unit), shape ``(L,)``.
    residual : ndarray
        The signal less the fitted lines, shape ``(N,)``.

    Examples
    --------
    >>> t = np.arange(3000) * 1e-3
    >>> lines, amplitudes, rest = refine_lines(np.cos(7.77 * t + 1.0), 1e-3, np.array([7.9]))
    >>> round(float(lines[0]), 4), round(float(amplitudes[0]), 4), float(np.abs(rest).max()) < 1e-6
    (7.77, 1.0, True)
    """
    t = np.arange(len(x)) * h
    t = t - t.mean()  # the derivative columns then stay uncorrelated with the sines
    start = np.asarray(lines, dtype=float)
    w = start.copy()
    limit = np.pi / (len(x) * h)  # a frequency moves at most half a bin in all
    c, s = _fit(x, t, w)
    for _ in range(sweeps):
        # one Gauss–Newton step on every amplitude and frequency together: lines a bin
        # apart pull on each other, so no line is moved with the others held
        phase = np.outer(t, w)
        cos, sin = np.cos(phase), np.sin(phase)
        residual = x - cos @ c - sin @ s
        slope = t[:, None] * (-sin * c + cos * s)
        step = np.linalg.lstsq(np.hstack([cos, sin, slope]), residual, rcond=None)[0]
        w = np.clip(w + step[2 * len(w) :], start - limit, start + limit)
        c, s = _fit(x, t, w)
    phase = np.outer(t, w)
    residual = x - np.cos(phase) @ c - np.sin(phase) @ s
    return w, np.hypot(c, s), residual


def _fit(x: np.ndarray, t: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares cosine and sine amplitudes at ``w`` (rad/s) over ``t`` (s)."""
    phase = np.outer(t, w)
    X = np.hstack([np.cos(phase), np.sin(phase)])
    coef = np.linalg.lstsq(X, x, rcond=None)[0]
    return coef[: len(w)], coef[len(w) :]


def broadband_band(x: np.ndarray, h: float) -> tuple[float, float] | None:
    """The band (rad/s) a broadband signal carries: where its Welch spectrum stays above
    :data:`BROADBAND_DROP` of its peak, the lowest and the highest such frequency.

    Parameters
    ----------
    x : ndarray
        The signal, trend removed, shape ``(N,)``.
    h : float
        Sample step (s).

    Returns
    -------
    tuple of float or None
        ``(low, high)`` (rad/s); None for a signal with no power.

    Examples
    --------
    >>> noise = np.random.default_rng(0).standard_normal(20000)
    >>> low, high = broadband_band(noise, 1e-3)
    >>> low < 10.0, high > 3000.0   # white: the whole band up to π/h
    (True, True)
    """
    segment = int(min(len(x), 2 ** int(np.log2(max(len(x) // 8, 16)))))
    frequency, psd = sp_signal.welch(x, fs=1.0 / h, nperseg=segment)
    if not np.any(psd[1:] > 0):
        return None
    above = np.flatnonzero(psd[1:] >= BROADBAND_DROP * psd[1:].max()) + 1
    omega = 2.0 * np.pi * frequency
    return float(omega[above[0]]), float(omega[above[-1]])
