"""The band a drive log can show the chain's modes in (rad/s): the one home of that rule.

Two limits bound it. The disturbance observer's ``G(s) = g / (s + g)`` still passes a
third of the reaction torque at :data:`BAND_PER_G` · g_dist (:func:`dob_band`), and the
sample step h leaves :data:`SAMPLE_BAND` / h (:func:`sample_band`: about a twentieth of
the sampling frequency, where a held step still follows a sine). The modes are sought
below the lower of the two, min(3·g_dist, 0.3/h) (:func:`search_band`); the
excitation's lines are checked against each. Beyond the lines, a mode is driven where
the current's power stands above its noise level near it (:func:`driven_modes`): a
closed loop's current carries power over a wide band, however few lines dominate it.
"""

from __future__ import annotations

import numpy as np

from arcosim.identification.excitation.periodic import (
    PERIOD_RECORDS,
    detection_threshold,
    noise_level,
)
from arcosim.identification.excitation.periodogram import hann_power

#: Highest clamped frequency sought, in units of g_dist (dimensionless).
BAND_PER_G = 3.0
#: Highest frequency the sample step leaves, times the step (rad per step).
SAMPLE_BAND = 0.3
#: A mode within this ratio of an excited frequency is driven by it (dimensionless): a
#: line within ±2ζω of a mode of damping ζ ≤ 5 % still drives it at −7 dB of its peak.
MODE_REACH = 1.1


def dob_band(g_dist: float) -> float:
    """Highest frequency (rad/s) the DOB of bandwidth ``g_dist`` (rad/s) leaves:
    :data:`BAND_PER_G` · ``g_dist``.

    Parameters
    ----------
    g_dist : float
        Bandwidth of the disturbance observer (rad/s).

    Returns
    -------
    float
        The band's top (rad/s).

    Examples
    --------
    >>> dob_band(100.0)
    300.0
    """
    return BAND_PER_G * g_dist


def sample_band(h: float) -> float:
    """Highest frequency (rad/s) the sample step ``h`` (s) leaves: :data:`SAMPLE_BAND` / h.

    Parameters
    ----------
    h : float
        Sample step (s).

    Returns
    -------
    float
        The band's top (rad/s).

    Examples
    --------
    >>> sample_band(1e-3)
    300.0
    """
    return SAMPLE_BAND / h


def search_band(g_dist: float, h: float) -> float:
    """Highest clamped frequency sought (rad/s): min(3·g_dist, 0.3/h), the lower of
    :func:`dob_band` and :func:`sample_band`.

    Parameters
    ----------
    g_dist : float
        Bandwidth of the disturbance observer (rad/s).
    h : float
        Sample step (s).

    Returns
    -------
    float
        The band's top (rad/s).

    Examples
    --------
    >>> search_band(50.0, 1e-3), search_band(200.0, 1e-3)  # the DOB's, the sample rate's
    (150.0, 300.0)
    """
    return min(dob_band(g_dist), sample_band(h))


def driven_modes(x: np.ndarray, h: float, modes: np.ndarray) -> np.ndarray:
    """Which modes the current drives: those near which (within a ratio
    :data:`MODE_REACH`) a bin of its Hann periodogram stands over the noise level there
    (:func:`~arcosim.identification.excitation.periodic.noise_level`, the lines' test) by
    the χ² threshold that noise alone passes once in
    :data:`~arcosim.identification.excitation.periodic.PERIOD_RECORDS` records
    anywhere in the band (:func:`~arcosim.identification.excitation.periodic.detection_threshold`,
    the rule the period's bins are held to): one noise bin taken for excitation would
    let a mode the record does not resolve through (a k_t 10 % high puts one at
    200–250 rad/s, over a multi-sine's lines to 150 rad/s).

    A broadband current stands over no local noise level (the level follows it); its
    band is read from its spectrum's shape instead
    (:func:`~arcosim.identification.excitation.spectrum.broadband_band`).

    Parameters
    ----------
    x : ndarray
        The current (A, any unit), shape ``(N,)``, step ``h``.
    h : float
        Sample step (s).
    modes : ndarray
        Mode frequencies (rad/s), shape ``(M,)``.

    Returns
    -------
    ndarray
        Boolean, shape ``(M,)``: driven.

    Examples
    --------
    A weak line at 27.3 rad/s under a strong one at 9.3 rad/s drives a mode at 27 rad/s;
    nothing drives one at 248 rad/s:

    >>> t = np.arange(20000) * 1e-3
    >>> x = 3.0 * np.sin(9.3 * t) + 0.02 * np.sin(27.3 * t)
    >>> x += 0.005 * np.random.default_rng(0).standard_normal(len(t))
    >>> driven_modes(x, 1e-3, np.array([27.0, 248.0])).tolist()
    [True, False]
    """
    x = np.asarray(x, dtype=float)
    t = np.arange(len(x)) * h
    x = x - np.polyval(np.polyfit(t, x, 1), t)
    power = hann_power(x)
    ratio = power[1:] / noise_level(power[1:])
    w = np.arange(1, len(power)) * 2.0 * np.pi / (len(x) * h)
    q = detection_threshold(len(ratio), 1.0 / PERIOD_RECORDS)
    driven = []
    for mode in np.asarray(modes, dtype=float):
        near = (w >= mode / MODE_REACH) & (w <= mode * MODE_REACH)
        driven.append(bool(np.any(ratio[near] > q)))
    return np.array(driven, dtype=bool)
