"""Lines the Hann window merged, told apart again by a least-squares search (offline).

Off the record's grid, lines under two bins (4π/T) apart share the Hann window's main
lobe: the periodogram shows one peak where two or more lines lie, and the one-pass fit
(:func:`~arcosim.identification.excitation.spectrum.spectral_lines`) puts one line there
and says where the rest lie
(:func:`~arcosim.identification.excitation.spectrum.unresolved_lines`). Above the
Rayleigh limit (one bin, 2π/T) the record holds them apart; what fails is the search:
the least-squares cost of lines a bin apart has local minima, and no start the
periodogram offers (its merged peaks sit between the lines) is near enough.

:func:`resolve_merged_lines` searches for them by alternating projection (Ziskind & Wax,
IEEE Trans. ASSP 36(10), 1988): over the band where lines merged, one line is added
where it lowers the least-squares cost most, and then each line in turn moves to the
frequency that, with every other line's amplitude fitted again, lowers it most: a
global search in one frequency at a time, on the signal decimated to the band. Every
frequency is then refined together by Gauss–Newton on the whole record. The count
grows while the new line is a played line: it lowers the sum of squares by more than
noise would once in 1/:data:`FALSE_BAND` records (the χ² threshold over the band's
bins), and every line in the band has a played line's amplitude. The count is taken
only when its lines are told apart (each two, and the lowest and 0, at least the
Rayleigh limit apart within three standard deviations of their separation, and that
separation over three) and it
explains the band (what it leaves there is noise: its power against the noise level
outside the band, by the χ² law at :data:`FALSE_BAND`); otherwise the one-pass count
stands, with where more lines lie.

Each check changes a result (40 log-spaced lines 3–150 rad/s, 0.075 A, off the grid:
seeds 1–8 in 20 s and 1–4 in 10 s, 5 mA of noise and none, ``tests/test_line_count.py``;
seeds 1–3 of a drive's current, 1 mA steps, ``tests/test_excitation_reading.py``). With
every check all 22 records of 20 s read 40 lines within 0.02 bin; in 10 s, where the
lowest lines lie half a bin apart, all 8 fall back to the one-pass count with its
places. Without the Rayleigh test two of those 10 s records, and without the noise test
four, read a confident wrong count. The drop's level, :data:`FALSE_BAND` like the band
test's, changes none of these records against the one-pass level (half a false line
per band).
"""

from __future__ import annotations

import numpy as np
from scipy import signal as sp_signal
from scipy.stats import chi2

from arcosim.identification.excitation.periodic import detection_threshold
from arcosim.identification.excitation.periodogram import hann_peaks, hann_power, line_worth

#: The Hann window's main lobe, half width (bins of 2π/T): lines closer than this to a
#: merged place share its peak; the band searched reaches this far past its lines.
MAIN_LOBE = 2.0
#: Alternating projection's frequency grid (fractions of a bin): the search needs only
#: to land in the right basin; Gauss–Newton refines to the noise's precision.
GRID_FRACTION = 1.0 / 16.0
#: Lines the search never places closer than this (bins): two sines nearer than half a
#: bin are nearly one column of the least squares, and their amplitudes cancel.
NEAREST = 0.5
#: The Hann window's equivalent noise bandwidth (bins): its bins' noise is correlated
#: over this width, so K bins hold 2K / 1.5 degrees of freedom of noise.
HANN_BANDWIDTH = 1.5
#: The band's residual is held to the noise level outside it at this false-alarm
#: probability (χ² over the band's degrees of freedom): a band the lines explain is
#: refused once in this many records' inverse.
FALSE_BAND = 1e-3
#: The least residual (relative to the signal's rms, dimensionless) a noise-free record
#: leaves: double-precision least squares over thousands of samples, and the
#: decimator's filter, leave about this much.
ROUNDING = 1e-9
#: Gauss–Newton stops when a step lowers the sum of squares by less than this many noise
#: variances (the sum over the samples' count), far below the χ² threshold a line must
#: pass (2·ln(K/10⁻³), about 20 noise variances), or by less than :data:`ROUNDING` of
#: it (a record without noise).
CONVERGED = 0.01
#: Samples ``scipy.signal.resample_poly`` leaves transient at each end of its output: its
#: default filter spans ten output samples either side.
DECIMATOR_TRANSIENT = 10
#: The lines' refinement (:func:`~arcosim.identification.excitation.spectrum.spectral_lines`)
#: and the search decimate to this many times the top frequency's share of the Nyquist
#: band (dimensionless, > 1: the decimating filter's margin).
DECIMATE_MARGIN = 2.5


def resolve_merged_lines(
    y: np.ndarray, h: float, lines: np.ndarray, places: np.ndarray, least: float, rayleigh: float
) -> tuple[np.ndarray, np.ndarray] | None:
    """The lines a window merged, told apart; ``None`` when the record cannot.

    Parameters
    ----------
    y : ndarray
        The signal, trend removed (decimated to the lines' band by
        ``scipy.signal.resample_poly``), shape ``(N,)``, step ``h``.
    h : float
        Its sample step (s).
    lines : ndarray
        The lines the one-pass fit found (rad/s), shape ``(L,)``.
    places : ndarray
        Where that fit left a line's worth of signal (rad/s), shape ``(U,)``, not empty.
    least : float
        The least amplitude of a played line (the signal's unit).
    rayleigh : float
        The record's Rayleigh limit 2π/T (rad/s), T its whole duration.

    Returns
    -------
    tuple of ndarray or None
        The lines (rad/s, ascending, shape ``(L',)``) and their amplitudes (the signal's
        unit), the merged ones told apart; ``None`` when no count explains the band with
        lines at least the Rayleigh limit apart.

    Examples
    --------
    Three lines 1.2 bins apart in 20 s, fitted as two with a place between:

    >>> h = 8e-3
    >>> t = np.arange(2500) * h
    >>> bin = 2 * np.pi / (2500 * h)
    >>> played = np.array([10.3, 11.5, 12.7]) * bin
    >>> y = np.sin(np.outer(t, played) + [0.3, 2.0, 4.1]).sum(axis=1)
    >>> one_pass, place = np.array([10.9, 12.5]) * bin, np.array([11.6]) * bin
    >>> found = resolve_merged_lines(y, h, one_pass, place, 0.5, bin)
    >>> np.round(found[0] / bin, 2), np.round(found[1], 2)
    (array([10.3, 11.5, 12.7]), array([1., 1., 1.]))
    """
    y = np.asarray(y, dtype=float)[DECIMATOR_TRANSIENT:-DECIMATOR_TRANSIENT]
    n = len(y)
    t = np.arange(n) * h
    t = t - t.mean()
    grid_step = 2.0 * np.pi / (n * h)  # this record's bin (rad/s)
    w, _, cost = _gauss_newton(y, t, np.sort(np.asarray(lines, dtype=float)))
    lo, hi = _band(_amplitudes(y, t, w)[2], h, np.asarray(places, dtype=float), least)
    # a line's fit lowers the sum of squares of noise alone by σ²·χ²₂: over the band's
    # bins, by 2·ln(K / FALSE_BAND) σ² once in 1/FALSE_BAND records
    threshold = 2.0 * detection_threshold(max(int((hi - lo) / grid_step), 1), FALSE_BAND)
    most = int((hi - lo) / rayleigh) + 1  # lines at the Rayleigh limit fill the band
    best = None
    while np.sum((w > lo) & (w < hi)) < most:
        inside = (w > lo) & (w < hi)
        searched = _search(y, t, h, w, inside, lo, hi, grid_step)
        trial = np.sort(np.concatenate([w[~inside], searched]))
        trial, amplitude, trial_cost = _gauss_newton(y, t, trial)
        variance = trial_cost / (n - 3 * len(trial) - 2)
        played = amplitude[(trial > lo) & (trial < hi)] >= least
        if cost - trial_cost <= threshold * variance or not np.all(played):
            break
        w, cost, best = trial, trial_cost, (trial, amplitude, variance)
    if best is None or not _told_apart(y, t, best[0], best[2], rayleigh):
        return None
    if not _explains_band(y, t, h, best[0], lo, hi):
        return None
    return best[0], best[1]


def _band(residual: np.ndarray, h: float, places: np.ndarray, least: float) -> tuple[float, float]:
    """The band (rad/s) to search: from the lowest place to the highest, grown through
    every bin of the residual that holds a played line's worth of signal within a main
    lobe of the band (where the one-pass fit left merged lines, named or not), then a
    main lobe on either side."""
    worth = np.flatnonzero(line_worth(hann_peaks(residual), len(residual), least))
    grid_step = 2.0 * np.pi / (len(residual) * h)
    lo, hi = float(places.min()) / grid_step, float(places.max()) / grid_step
    while True:
        below = worth[(worth < lo) & (worth >= lo - MAIN_LOBE)]
        above = worth[(worth > hi) & (worth <= hi + MAIN_LOBE)]
        if not len(below) and not len(above):
            break
        lo = float(below.min()) if len(below) else lo
        hi = float(above.max()) if len(above) else hi
    return max(lo - MAIN_LOBE, 0.5) * grid_step, (hi + MAIN_LOBE) * grid_step


def _search(
    y: np.ndarray,
    t: np.ndarray,
    h: float,
    w: np.ndarray,
    inside: np.ndarray,
    lo: float,
    hi: float,
    grid_step: float,
) -> np.ndarray:
    """The band's lines and one more, by alternating projection on ``y`` decimated to the
    band, the lines outside it far from the band subtracted, the near ones projected out."""
    near = ~inside & (w > lo - 2 * MAIN_LOBE * grid_step) & (w < hi + 2 * MAIN_LOBE * grid_step)
    far = ~inside & ~near
    c, s = _amplitudes(y, t, w)[:2]
    z = y - np.cos(np.outer(t, w[far])) @ c[far] - np.sin(np.outer(t, w[far])) @ s[far]
    q = max(int(np.pi / (h * DECIMATE_MARGIN * (hi + 2 * MAIN_LOBE * grid_step))), 1)
    if q > 1:
        z = sp_signal.resample_poly(z, 1, q)[DECIMATOR_TRANSIENT:-DECIMATOR_TRANSIENT]
        t = t[::q][DECIMATOR_TRANSIENT:][: len(z)]
        z = z[: len(t)]
    grid = np.arange(lo, hi, GRID_FRACTION * grid_step)
    fixed = w[near]
    free = list(w[inside])
    free.append(_best(z, t, fixed, np.array(free), grid, grid_step))
    for _ in range(len(grid)):  # a sweep moves a line or stops; each sweep lowers the cost
        moved = False
        for j in range(len(free)):
            others = np.array(free[:j] + free[j + 1 :])
            best = _best(z, t, fixed, others, grid, grid_step)
            moved |= abs(best - free[j]) > 0.5 * GRID_FRACTION * grid_step
            free[j] = best
        if not moved:
            break
    return np.array(free)


def _best(
    z: np.ndarray,
    t: np.ndarray,
    fixed: np.ndarray,
    others: np.ndarray,
    grid: np.ndarray,
    grid_step: float,
) -> float:
    """The grid frequency (rad/s) at which one more sine lowers the sum of squares most,
    with the ``fixed`` and ``others`` sines (and a constant and a ramp) projected out; not
    within :data:`NEAREST` bins of another."""
    kept = np.concatenate([fixed, others])
    basis = np.hstack([np.ones((len(t), 1)), t[:, None], *_columns(t, kept)])
    Q = np.linalg.qr(basis)[0]
    r = z - Q @ (Q.T @ z)
    C, S = _columns(t, grid)
    C, S = C - Q @ (Q.T @ C), S - Q @ (Q.T @ S)
    a, b = C.T @ r, S.T @ r
    cc, ss, cs = (np.einsum("ij,ij->j", u, v) for u, v in ((C, C), (S, S), (C, S)))
    gain = (ss * a * a - 2 * cs * a * b + cc * b * b) / np.maximum(cc * ss - cs**2, 1e-300)
    if len(others):
        crowded = np.min(np.abs(grid[:, None] - others[None, :]), axis=1) < NEAREST * grid_step
        gain[crowded] = -np.inf
    return float(grid[np.argmax(gain)])


def _columns(t: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    phase = np.outer(t, w)
    return np.cos(phase), np.sin(phase)


def _amplitudes(
    y: np.ndarray, t: np.ndarray, w: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cosine and sine amplitudes at ``w`` with a constant and a ramp, by least squares;
    and the residual."""
    cos, sin = _columns(t, w)
    X = np.hstack([cos, sin, np.ones((len(t), 1)), t[:, None] / max(abs(t[0]), 1e-300)])
    coef = np.linalg.lstsq(X, y, rcond=None)[0]
    return coef[: len(w)], coef[len(w) : 2 * len(w)], y - X @ coef


def _jacobian(t: np.ndarray, w: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The residual's derivatives by the cosine and sine amplitudes, the constant, the
    ramp and the frequencies, shape ``(N, 3L + 2)``."""
    cos, sin = _columns(t, w)
    ramp = t[:, None] / max(abs(t[0]), 1e-300)
    return np.hstack([cos, sin, np.ones((len(t), 1)), ramp, t[:, None] * (-sin * c + cos * s)])


def _gauss_newton(
    y: np.ndarray, t: np.ndarray, w: np.ndarray
) -> tuple[np.ndarray, np.ndarray, float]:
    """Every frequency refined together (Levenberg–Marquardt, the amplitudes fitted again
    at each step): the frequencies, their amplitudes and the sum of squares."""
    c, s, r = _amplitudes(y, t, w)
    cost, damping = float(r @ r), 1e-4
    for _ in range(100):
        J = _jacobian(t, w, c, s)
        JTJ, g = J.T @ J, J.T @ r
        diagonal = np.diag(np.diag(JTJ))
        for _ in range(12):
            step = np.linalg.lstsq(JTJ + damping * diagonal, g, rcond=None)[0]
            trial = w + step[2 * len(w) + 2 :]
            ct, st, rt = _amplitudes(y, t, trial)
            if rt @ rt < cost:
                break
            damping *= 10.0
        else:
            break
        gain = cost - float(rt @ rt)
        w, c, s, r, cost, damping = trial, ct, st, rt, float(rt @ rt), max(damping / 10.0, 1e-12)
        if gain <= max(CONVERGED * cost / len(y), ROUNDING * cost):
            break
    order = np.argsort(w)
    return w[order], np.hypot(c, s)[order], cost


def _explains_band(
    y: np.ndarray, t: np.ndarray, h: float, w: np.ndarray, lo: float, hi: float
) -> bool:
    """Whether what the lines ``w`` (rad/s) leave in the band ``lo`` … ``hi`` (rad/s) is
    noise: its mean Hann power within the χ² law at :data:`FALSE_BAND` of the noise
    level outside the band."""
    r = _amplitudes(y, t, w)[2]
    power = hann_power(r)
    at = np.arange(len(power)) * 2.0 * np.pi / (len(r) * h)
    band = (at > lo) & (at < hi)
    noise = np.median(power[1:][~band[1:]]) / np.log(2.0)  # an exponential's median: ln 2 × mean
    rounding = (ROUNDING * np.std(y)) ** 2 * np.sum(np.hanning(len(r)) ** 2)
    noise = max(noise, rounding)  # a record without noise: what the arithmetic leaves
    dof = 2.0 * band.sum() / HANN_BANDWIDTH
    return bool(power[band].mean() <= noise * chi2.ppf(1.0 - FALSE_BAND, dof) / dof)


def _told_apart(
    y: np.ndarray, t: np.ndarray, w: np.ndarray, variance: float, rayleigh: float
) -> bool:
    """Whether the lines ``w`` (rad/s) are told apart: each two, and the lowest and 0 (the
    constant and the ramp), at least the Rayleigh limit (rad/s) apart within three
    standard deviations of their separation, and distinct (the separation over three),
    the deviations from the fit's covariance with the residual's ``variance``."""
    c, s, _ = _amplitudes(y, t, w)
    J = _jacobian(t, w, c, s)
    covariance = variance * np.linalg.pinv(J.T @ J)[2 * len(w) + 2 :, 2 * len(w) + 2 :]
    d = np.diag(covariance)
    spread = np.sqrt(np.maximum(d[1:] + d[:-1] - 2 * np.diag(covariance, 1), 0.0))
    # the lowest from 0 as well: under one period in the record a line is the trend's
    spread, apart = np.r_[np.sqrt(max(d[0], 0.0)), spread], np.r_[w[0], np.diff(w)]
    return bool(np.all((apart + 3.0 * spread >= rayleigh) & (apart > 3.0 * spread)))
