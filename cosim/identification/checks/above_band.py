"""What lies above the band: is the motor's response above 3·g_dist that of a drive with
no mode there? (offline)

The disturbance observer hides what lies above 3·g_dist from the fit
(:func:`~arcosim.identification.excitation.band.dob_band`), so an excitation reaching
above it is a doubt only when something lies there. Above every mode of a chain the
motor sees its own inertia, on the springs' sum K to masses that hardly move, and its
damping: the angle's response to the current is the smooth k_t/(J_m s² + D s + K), with
no resonance or antiresonance. A mode above the band adds such a pair to it.

:func:`above_band_test` measures the frequency response θ_m/i_a above the band (the
record cut in segments: its whole periods for a periodic excitation, else
:data:`SEGMENTS` Hann-windowed pieces), and the noise of each bin's estimate from the
segments' spread (the best linear approximation's noise and distortion alike, as
Pintelon & Schoukens read them), fits the mode-free form to it by weighted least
squares (:func:`mode_free_basis`) and tests the weighted misfit: under a drive with no
mode above the band twice the misfit is χ² with 2B − p degrees of freedom (B bins, p
parameters), so :attr:`AboveBand.mode` says a mode lies there when that χ² exceeds its
1 − :data:`LEVEL` quantile. With too little excitation above the band (fewer than
:data:`LEAST_BINS` bins where the response stands above its noise) it cannot decide
(None), and the band check keeps its doubt.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

from arcosim.identification.excitation.periodic import detection_threshold

#: The test's level (dimensionless): a drive with no mode above the band is doubted on
#: one record in a thousand.
LEVEL = 1e-3
#: Segments a record that is not of whole periods is cut in (a count): each bin's noise
#: is read from their spread with 2(SEGMENTS − 1) degrees of freedom (30: the
#: estimate's own spread adds under 7 % to the statistic's mean), at a bin width 16 ×
#: the record's (1.6 Hz over 10 s), still fine beside a mode above a 300 rad/s band.
SEGMENTS = 16
#: A record of whole periods is cut in its periods when it holds at least this many (a
#: count; fewer leave each bin's noise too few degrees of freedom, see :data:`SEGMENTS`).
LEAST_SEGMENTS = 8
#: Least bins (a count) above the band where the response stands above its noise for
#: the test to decide: twice the mode-free form's parameters, so the misfit keeps as
#: many degrees of freedom as the fit takes.
LEAST_BINS = 10


@dataclass(frozen=True)
class AboveBand:
    """The test of what lies above the band (see :func:`above_band_test`).

    Attributes
    ----------
    statistic : float
        Twice the weighted misfit of the mode-free form, corrected for the noise
        estimate's own spread (dimensionless; χ² with ``dof`` degrees of freedom under
        a drive with no mode above the band).
    dof : int
        Its degrees of freedom (a count).
    p_value : float
        The probability of a statistic this large without a mode (dimensionless).
    bins : int
        Bins above the band tested (a count).
    top : float
        The band's top (rad/s).

    Examples
    --------
    >>> AboveBand(210.0, 200, 0.3, 103, 300.0).mode
    False
    """

    statistic: float
    dof: int
    p_value: float
    bins: int
    top: float

    @property
    def mode(self) -> bool:
        """True when the response above the band departs from the mode-free form at
        level :data:`LEVEL`: a mode lies there."""
        return self.p_value < LEVEL

    @property
    def limit(self) -> float:
        """The statistic's 1 − :data:`LEVEL` quantile under a drive without a mode above
        the band (dimensionless).

        Examples
        --------
        >>> round(AboveBand(210.0, 200, 0.3, 103, 300.0).limit)
        268
        """
        return float(stats.chi2.isf(LEVEL, self.dof))

    def text(self) -> str:
        """The statistic for the user.

        Examples
        --------
        >>> AboveBand(910.0, 200, 1e-90, 103, 300.0).text()[:60]
        'χ² = 910 over 103 bins above 300 rad/s, where a drive withou'
        """
        return (
            f"χ² = {self.statistic:.3g} over {self.bins} bins above {self.top:.3g} rad/s, "
            f"where a drive without a mode exceeds {self.limit:.3g} once in "
            f"{1.0 / LEVEL:.0f} records"
        )


def mode_free_basis(z: np.ndarray, h: float) -> np.ndarray:
    """The mode-free form's basis at ``z`` = e^(jωh): the zero-order-hold transforms of
    1/s, 1/s², 1/s³, 1/s⁴ (the expansion of 1/(J s² + D s + K) above its poles, with 1/s
    for a lag under a step), and a constant (the current and the angle may be sampled
    up to a step apart).

    Parameters
    ----------
    z : ndarray
        Points on the unit circle, shape ``(B,)``, none at 1.
    h : float
        Sample step (s).

    Returns
    -------
    ndarray
        Complex, shape ``(B, 5)``.

    Examples
    --------
    Over one step a hold's double integrator is h²(z + 1)/(2(z − 1)²):

    >>> z = np.exp(1j * np.array([0.3]))
    >>> basis = mode_free_basis(z, 1e-3)
    >>> bool(np.isclose(basis[0, 1], 1e-6 * (z[0] + 1) / (2 * (z[0] - 1) ** 2)))
    True
    """
    u = z - 1.0
    return np.stack(
        [
            h / u,
            h**2 * (z + 1) / (2 * u**2),
            h**3 * (z**2 + 4 * z + 1) / (6 * u**3),
            h**4 * (z**3 + 11 * z**2 + 11 * z + 1) / (24 * u**4),
            np.ones_like(z),
        ],
        axis=1,
    )


def _segments(
    x: np.ndarray, y: np.ndarray, periods: int
) -> tuple[np.ndarray, np.ndarray, int, int]:
    """The segments' spectra of ``x`` and ``y`` (shape ``(N,)``): by whole periods
    (rectangular, every bin) when the record holds :data:`LEAST_SEGMENTS` of them, else
    :data:`SEGMENTS` Hann-windowed pieces (every second bin: neighbours correlate); each
    segment's mean and linear trend removed. Returns the spectra, shape ``(P, L//2 + 1)``
    each, the segment length L and the bin stride."""
    count = periods if periods >= LEAST_SEGMENTS else SEGMENTS
    length = len(x) // count
    window = np.ones(length) if periods >= LEAST_SEGMENTS else np.hanning(length)
    stride = 1 if periods >= LEAST_SEGMENTS else 2
    n = np.arange(length)
    spectra = []
    for signal in (x, y):
        pieces = signal[: count * length].reshape(count, length)
        trend = np.polynomial.polynomial.polyfit(n, pieces.T, 1)
        pieces = pieces - (trend[0][:, None] + trend[1][:, None] * n)
        spectra.append(np.fft.rfft(pieces * window, axis=1))
    return spectra[0], spectra[1], length, stride


def above_band_test(
    i_a: np.ndarray, theta_m: np.ndarray, h: float, top: float, high: float, periods: int = 0
) -> AboveBand | None:
    """Whether the motor's response above ``top`` is that of a drive with no mode there
    (the module doc states the test).

    Parameters
    ----------
    i_a : ndarray
        Motor current (A), shape ``(N,)``.
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.
    h : float
        Sample step (s).
    top : float
        The band's top, 3·g_dist (rad/s).
    high : float
        The highest frequency the excitation carries (rad/s).
    periods : int
        Whole periods the record holds (a count; 0: not periodic).

    Returns
    -------
    AboveBand or None
        The statistic; None when the record cannot decide (fewer than
        :data:`LEAST_BINS` bins above ``top`` where the response stands above its
        noise).

    Examples
    --------
    A rigid motor under white current, and the same with a coupling's mode at 700 rad/s
    (its antiresonance at 500 rad/s):

    >>> from scipy import signal
    >>> rng = np.random.default_rng(0)
    >>> h, current = 1e-3, rng.standard_normal(20000)
    >>> rigid = signal.lsim(([0.0406], [2e-5, 1e-4, 0.0]), current, np.arange(20000) * h)
    >>> theta = rigid[1] + 1e-5 * rng.standard_normal(20000)
    >>> above_band_test(current, theta, h, 300.0, 1500.0).mode
    False
    >>> coupled = ([0.0406 * 2e-5, 0.0, 0.0406 * 5.0],
    ...            np.polymul([2e-5, 0.0, 0.0], [2e-5 * 2e-5, 0.0, 5.0 * 4e-5]))
    >>> flexible = signal.lsim(coupled, current, np.arange(20000) * h)[1]
    >>> above_band_test(current, flexible + 1e-5 * rng.standard_normal(20000), h,
    ...                 300.0, 1500.0).mode
    True
    """
    i_a, theta_m = np.asarray(i_a, dtype=float), np.asarray(theta_m, dtype=float)
    if len(i_a) < 4 * LEAST_BINS * max(periods, SEGMENTS):  # a segment under 2·LEAST_BINS bins
        return None
    current, angle, length, stride = _segments(i_a, theta_m, periods)
    count = len(current)
    w = 2.0 * np.pi * np.fft.rfftfreq(length, h)
    tested = np.flatnonzero((w > top) & (w <= high) & (w < np.pi / h))[::stride]
    if len(tested) < LEAST_BINS:
        return None
    current, angle, w = current[:, tested], angle[:, tested], w[tested]
    power = np.sum(np.abs(current) ** 2, axis=0)
    if not np.all(power > 0):
        return None
    frf = np.sum(angle * current.conj(), axis=0) / power
    spread = np.sum(np.abs(angle - frf * current) ** 2, axis=0) / (count - 1)
    weight = power / np.maximum(spread, 1e-300)  # 1 / the estimate's variance
    # where the response stands above its noise (the χ² detection threshold of a line)
    if np.sum(weight * np.abs(frf) ** 2 > detection_threshold(len(w))) < LEAST_BINS:
        return None
    basis = mode_free_basis(np.exp(1j * w * h), h) * np.sqrt(weight)[:, None]
    target = frf * np.sqrt(weight)
    design = np.vstack([basis.real, basis.imag])
    rhs = np.concatenate([target.real, target.imag])
    coefficients = np.linalg.lstsq(design, rhs, rcond=None)[0]
    misfit = float(np.sum((rhs - design @ coefficients) ** 2))
    m = 2 * (count - 1)  # the noise estimate's degrees of freedom per bin
    statistic = 2.0 * misfit * (m - 2) / m
    dof = 2 * len(w) - design.shape[1]
    p_value = float(stats.chi2.sf(statistic, dof))
    return AboveBand(statistic, dof, p_value, len(w), float(top))
