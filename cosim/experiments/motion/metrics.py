"""How a point-to-point move is scored: settling, residual vibration, current, limit cycle.

Every score takes the run's sample times and one signal; the move starts at ``start``
and aims at ``target``. The bands are relative to the move's length (±1 % of a 1 rad
move is ±10 mrad; one count of a 2000-count encoder is 3.1 mrad, 0.3 % of a radian).
"""

from __future__ import annotations

import math

import numpy as np


def settling_time(
    time: np.ndarray,
    angle: np.ndarray,
    target: float,
    band: float,
    start: float = 0.0,
) -> float:
    """Time from ``start`` after which ``angle`` stays within ``band`` of ``target``.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``, increasing.
    angle : ndarray
        The controlled angle (rad), shape ``(N,)``.
    target : float
        Where the move ends (rad).
    band : float
        Half-width of the band (rad), > 0: e.g. 1 % of the move's length.
    start : float
        When the move starts (s).

    Returns
    -------
    float
        The settling time (s): from ``start`` to the first sample after the last one
        outside the band; 0 when no sample from ``start`` on is outside; ``inf`` when
        the last sample is outside (never settled within the run).

    Examples
    --------
    >>> t = np.arange(6) * 0.5
    >>> settling_time(t, np.array([0.0, 0.5, 0.97, 1.02, 0.995, 1.001]), 1.0, 0.01)
    2.0
    """
    if not band > 0:
        raise ValueError(f"band must be > 0 rad, got {band}")
    after = time >= start
    outside = np.flatnonzero(after & (np.abs(angle - target) > band))
    if outside.size == 0:
        return 0.0
    last = int(outside[-1])
    if last == len(time) - 1:
        return math.inf
    return float(time[last + 1] - start)


def residual_rms(time: np.ndarray, angle: np.ndarray, target: float, window: float) -> float:
    """Rms of ``angle`` about ``target`` over the run's last ``window`` seconds (rad).

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    angle : ndarray
        The controlled angle (rad), shape ``(N,)``.
    target : float
        Where the move ends (rad).
    window : float
        Length of the window at the end of the run (s), > 0.

    Returns
    -------
    float
        rms(angle − target) over ``time > time[-1] − window`` (rad): residual vibration
        and static error together.

    Examples
    --------
    >>> t = np.linspace(0.0, 6.0, 6001)
    >>> round(residual_rms(t, 1.0 + 0.01 * np.sin(2 * np.pi * t), 1.0, 2.0), 5)
    0.00707
    """
    if not window > 0:
        raise ValueError(f"window must be > 0 s, got {window}")
    inside = time > time[-1] - window
    return float(np.sqrt(np.mean((angle[inside] - target) ** 2)))


def peak_current(current: np.ndarray) -> float:
    """The largest |current| of a run (A), ``current`` of shape ``(N,)``.

    Examples
    --------
    >>> peak_current(np.array([0.1, -0.4, 0.2]))
    0.4
    """
    return float(np.max(np.abs(current)))


def limit_cycle_counts(
    time: np.ndarray, theta_m: np.ndarray, encoder_cpr: int, window: float
) -> float:
    """Peak-to-peak motor angle over the run's last ``window`` seconds, in encoder counts.

    A motor held still reads a constant count (0); one dithering between two
    neighbouring counts reads 1, the least a quantized angle can show of any motion.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    theta_m : ndarray
        The motor angle as the encoder gives it (rad, whole counts), shape ``(N,)``.
    encoder_cpr : int
        Counts per revolution (a count), > 0.
    window : float
        Length of the window at the end of the run (s), > 0.

    Returns
    -------
    float
        (max − min) of ``theta_m`` over the window, in counts.

    Examples
    --------
    >>> count = 2 * np.pi / 2000
    >>> t = np.arange(5) * 1.0
    >>> limit_cycle_counts(t, np.array([0, 0, 5, 6, 5]) * count, 2000, 2.5)
    1.0
    """
    if encoder_cpr <= 0:
        raise ValueError(f"encoder_cpr must be > 0 counts, got {encoder_cpr}")
    inside = time > time[-1] - window
    span = float(np.ptp(theta_m[inside]))
    return round(span * encoder_cpr / (2.0 * math.pi), 6)
