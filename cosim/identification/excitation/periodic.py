"""A record of whole periods: the period, and the lines on its harmonics (offline).

A periodic excitation (a Schroeder or random-phase multi-sine played period after
period, a square wave) recorded over M whole periods of P samples puts every line it
plays, and everything the drive adds in step with it (friction's and the current
loop's harmonics), exactly on the record's DFT bins k·M; the bins between hold the
noise alone. :func:`whole_periods` reads M from the greatest common divisor of the
bins that stand far above the noise (no window: on the grid a line leaks nothing), and
:func:`harmonic_lines` tests each harmonic bin against the noise level those bins
between give, by the χ² law of a noise bin (:func:`detection_threshold`): the
period-averaged periodogram, for the sum over M periods is the record's DFT at k·M.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

#: Expected count of noise bins (a count) a detection over the whole band lets through
#: as lines: the threshold :func:`detection_threshold` sets makes the expected number of
#: false lines under one half, so a record of noise alone reads as no line most times.
FALSE_LINES = 0.5
#: The period rests on bins a noise bin reaches once in this many records of the same
#: length (a count): the greatest common divisor of the bins fails on one false bin,
#: so its bins are held to a false-alarm probability 1/PERIOD_RECORDS over the record.
PERIOD_RECORDS = 200.0
#: Least whole periods (a count) a record must hold to be read as periodic: with one,
#: every bin is a harmonic, and the bins between, which give the noise, do not exist.
LEAST_PERIODS = 2
#: Lines sit on the record's grid when :data:`ON_GRID_SHARE` of the lines resolved (over
#: two bins from their neighbours) lie within this many bins of a grid line
#: (dimensionless): off-grid lines lie anywhere within half a bin, each this close by
#: chance with probability 0.1, and a resolved line's refined frequency errs by far less
#: (1e-3 bin at a signal-to-noise ratio of 10 over 20000 samples; a line merged with a
#: neighbour, a bin or two away, by more: hence a share, not all).
ON_GRID = 0.05
#: Share of the resolved lines (dimensionless) that must lie on the grid: 8 of 10
#: off-grid lines fall within :data:`ON_GRID` by chance in under one record in 10^6.
ON_GRID_SHARE = 0.8
#: Least resolved lines (a count) on which the grid is judged.
ON_GRID_LINES = 10
#: The noise level at a bin is read over this many bins around it (a count, odd): a
#: drive's current noise is coloured by its loops (the motor bench's varies tenfold over
#: its band), so it is read locally, over enough bins that its quartile stands within
#: about 12 % of its value (√(p(1−p)/N) / (f(x_p)·x_p) for the exponential law).
LEVEL_BINS = 257
#: The noise level is read from this quantile of the bins around (dimensionless): an
#: exponential variable's quantile p is −ln(1 − p) times its mean, and the lower
#: quartile stays on the noise while lines and their main lobes fill up to three
#: quarters of the bins (a multi-sine's dense low end, three bins per line under a
#: Hann window, fills half).
LEVEL_QUANTILE = 0.25


def detection_threshold(bins: int, false_lines: float = FALSE_LINES) -> float:
    """The power ratio over the noise level (its mean per bin) a bin must exceed to
    count as a line, of ``bins`` bins tested, so that noise alone passes on
    ``false_lines`` bins on average.

    A noise bin's periodogram (any window) is |X|² with X complex Gaussian: σ²·χ²₂/2,
    exponential, P(|X|² > q·σ²) = e^(−q); over ``bins`` bins the expected false lines
    are bins·e^(−q), so q = ln(bins / false_lines).

    Parameters
    ----------
    bins : int
        Bins tested (a count).
    false_lines : float
        Expected false lines (a count) over them.

    Returns
    -------
    float
        q (dimensionless power ratio).

    Examples
    --------
    >>> round(detection_threshold(10000), 2)   # a 20 s record at 1 kHz
    9.9
    """
    return math.log(max(bins, 1) / false_lines)


def noise_level(power: np.ndarray) -> np.ndarray:
    """The noise level at each bin: the mean power of a noise bin there (the
    periodogram's unit), from the :data:`LEVEL_QUANTILE` quantile of ``power`` (shape
    ``(K,)``) over :data:`LEVEL_BINS` bins around it, most of them noise (an
    exponential variable's quantile p is −ln(1 − p) times its mean); shape ``(K,)``.

    Examples
    --------
    >>> noise = np.random.default_rng(0).standard_normal((2, 20000))
    >>> level = noise_level(noise[0] ** 2 + noise[1] ** 2)   # mean power 2
    >>> round(float(np.mean(level)), 1), bool(np.percentile(np.abs(level / 2 - 1), 95) < 0.3)
    (2.0, True)
    """
    power = np.asarray(power, dtype=float)
    size = min(LEVEL_BINS, len(power) | 1)
    quantile = ndimage.percentile_filter(power, 100 * LEVEL_QUANTILE, size=size, mode="reflect")
    return np.maximum(quantile / -math.log1p(-LEVEL_QUANTILE), 1e-300)


def whole_periods(x: np.ndarray) -> int:
    """How many whole periods M ≥ :data:`LEAST_PERIODS` the record holds, or 0.

    The bins whose power stands :func:`detection_threshold` over the noise level with
    1/:data:`PERIOD_RECORDS` false bins expected are the excitation's strongest lines;
    their greatest common divisor M is the count of periods when it divides the record's
    length (then M periods of N/M samples).

    Parameters
    ----------
    x : ndarray
        The signal, mean removed, shape ``(N,)``.

    Returns
    -------
    int
        M (a count), or 0 when the record does not hold whole periods.

    Examples
    --------
    >>> n = np.arange(4000)
    >>> x = np.sin(2 * np.pi * 11 * n / 400) + np.sin(2 * np.pi * 12 * n / 400 + 1.0)
    >>> whole_periods(x + 0.01 * np.random.default_rng(0).standard_normal(4000))
    10
    """
    power = np.abs(np.fft.rfft(x)) ** 2
    level = noise_level(power[1:])
    q = detection_threshold(len(power) - 1, 1.0 / PERIOD_RECORDS)
    strong = np.flatnonzero(power[1:] > q * level) + 1
    if len(strong) == 0:
        return 0
    m = int(np.gcd.reduce(strong))
    return m if m >= LEAST_PERIODS and len(x) % m == 0 else 0


def on_grid(lines: np.ndarray, resolution: float) -> bool:
    """Whether ``lines`` (rad/s, ascending, shape ``(L,)``) sit on the record's grid of
    ``resolution`` (2π/T, rad/s): :data:`ON_GRID_SHARE` of the lines over two bins from
    their neighbours (the ones a Hann window resolves) within :data:`ON_GRID` bins of a
    grid line, judged on :data:`ON_GRID_LINES` of them at least.

    Examples
    --------
    >>> grid = 2 * np.pi / 20.0
    >>> lines = np.arange(10, 100, 3) * grid
    >>> on_grid(lines + 1e-4, grid), on_grid(lines * 1.001, grid)
    (True, False)
    """
    position = np.asarray(lines, dtype=float) / resolution
    gaps = np.diff(position)
    apart = np.ones(len(position), dtype=bool)
    apart[1:] &= gaps > 2.0
    apart[:-1] &= gaps > 2.0
    resolved = position[apart]
    close = np.abs(resolved - np.rint(resolved)) <= ON_GRID
    return len(resolved) >= ON_GRID_LINES and float(np.mean(close)) >= ON_GRID_SHARE


def harmonic_lines(x: np.ndarray, periods: int) -> tuple[np.ndarray, np.ndarray, float]:
    """The harmonics of a record of ``periods`` whole periods that stand above the noise.

    The noise level is read from the bins between the harmonics (their local lower
    quartile, :func:`noise_level`), or, for one period (lines on the record's grid), from
    all bins, the lines filling under half of them; a harmonic counts when its power exceeds
    :func:`detection_threshold` times it, the threshold set over the harmonic bins
    tested.

    Parameters
    ----------
    x : ndarray
        The signal, mean removed, shape ``(N,)``, N a multiple of ``periods``.
    periods : int
        Whole periods in the record (a count, :func:`whole_periods`), 1 for lines on
        the record's grid.

    Returns
    -------
    harmonics : ndarray
        The harmonics found (a count per period: k for the line at k periods per
        period), ascending, shape ``(L,)``.
    amplitudes : ndarray
        Their amplitudes (the signal's unit), shape ``(L,)``.
    share : float
        Share of the signal's power on the harmonics found (dimensionless, 0 … 1).

    Examples
    --------
    >>> n = np.arange(4000)
    >>> x = np.sin(2 * np.pi * 11 * n / 400) + 0.5 * np.sin(2 * np.pi * 12 * n / 400 + 1.0)
    >>> x += 0.01 * np.random.default_rng(2).standard_normal(4000)
    >>> k, a, share = harmonic_lines(x, 10)
    >>> k, np.round(a, 3), round(share, 3)
    (array([11, 12]), array([1. , 0.5]), 1.0)
    """
    spectrum = np.fft.rfft(x)
    power = np.abs(spectrum) ** 2
    on = np.zeros(len(power), dtype=bool)
    on[::periods] = True
    on[0] = False
    between = np.flatnonzero(~on[1:]) + 1 if periods > 1 else np.arange(1, len(power))
    level = np.interp(np.arange(len(power)), between, noise_level(power[between]))
    q = detection_threshold(int(np.sum(on)))
    found = np.flatnonzero(on & (power > q * level))
    scale = np.full(len(found), 2.0 / len(x))
    if len(x) % 2 == 0:
        scale[found == len(power) - 1] = 1.0 / len(x)  # the Nyquist bin is real
    share = float(power[found].sum() / max(power[1:].sum(), 1e-300))
    return found // periods, np.abs(spectrum[found]) * scale, share
