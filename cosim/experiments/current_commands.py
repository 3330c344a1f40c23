"""Current commands (A) sampled at the communication steps, for scripts and scenarios.

Thin array wrappers over :mod:`arcosim.fmu.flexchain.waveforms`, the standard-library
implementation that the ExcitationSource FMU runs too. Every function takes the
step times ``t`` (s, shape ``(N,)``) and returns the current held over each step
(shape ``(N,)``).
"""

from __future__ import annotations

import numpy as np

from arcosim.fmu.flexchain import waveforms as _signals


def rigid_maneuver(
    t: np.ndarray,
    amplitude: float = 3.0,
    frequency: float = 2.1,
    periods: int = 8,
    ramp_periods: int = 3,
) -> np.ndarray:
    """A back-and-forth maneuver far below the first mode, without drift or ringing.

    The current is proportional to the acceleration of ``w(t) sin(ω t)``, ``w`` a
    raised-cosine window of ``ramp_periods`` periods each side, so the chain swings
    about its start and comes back to rest there (mode 1, eq. 17–21); see
    :func:`arcosim.fmu.flexchain.waveforms.rigid_maneuver`.

    Parameters
    ----------
    t : ndarray
        Step times (s), shape ``(N,)``.
    amplitude : float
        Peak current (A), well above f_c / k_t (the current that overcomes friction).
    frequency : float
        Maneuver frequency ω (rad/s), about an eighth of the first mode.
    periods : int
        Total length in periods, ramps included (a count).
    ramp_periods : int
        Length of each ramp in periods (a count).

    Returns
    -------
    ndarray
        Current held over each step (A), shape ``(N,)``; 0 after the maneuver.

    Examples
    --------
    >>> t = np.arange(0.0, 30.0, 1e-3)
    >>> i = arcosim.rigid_maneuver(t, amplitude=3.0, frequency=2.1)
    >>> bool(abs(i).max() <= 3.0 * 1.5), float(i[-1])
    (True, 0.0)
    """
    return np.array(
        [_signals.rigid_maneuver(x, amplitude, frequency, periods, ramp_periods) for x in t]
    )


def multisine(
    t: np.ndarray, amplitude: float, frequencies: np.ndarray, seed: int = 0
) -> np.ndarray:
    """A sum of sines with random phases, scaled to a peak current.

    Parameters
    ----------
    t : ndarray
        Step times (s), shape ``(N,)``.
    amplitude : float
        Peak current (A): the sum never exceeds it.
    frequencies : array_like
        The lines (rad/s), shape ``(L,)``.
    seed : int
        Seed of the random phases (the same seed, the same signal); an index.

    Returns
    -------
    ndarray
        Current held over each step (A), shape ``(N,)``.

    Examples
    --------
    >>> t = np.arange(0.0, 2.0, 1e-3)
    >>> i = arcosim.multisine(t, 1.0, np.geomspace(3.0, 150.0, 40))
    >>> i.shape, bool(abs(i).max() <= 1.0)
    ((2000,), True)
    """
    frequencies = [float(w) for w in frequencies]
    phases = _signals.multisine_phases(len(frequencies), seed)
    return np.array([_signals.multisine(x, amplitude, frequencies, phases) for x in t])


def chirp(t: np.ndarray, amplitude: float, w0: float, w1: float, duration: float) -> np.ndarray:
    """A linear frequency sweep.

    Parameters
    ----------
    t : ndarray
        Step times (s), shape ``(N,)``.
    amplitude : float
        Peak current (A).
    w0, w1 : float
        Start and end frequency (rad/s).
    duration : float
        Length of the sweep (s).

    Returns
    -------
    ndarray
        Current held over each step (A), shape ``(N,)``.

    Examples
    --------
    >>> t = np.arange(0.0, 5.0, 1e-3)
    >>> i = arcosim.chirp(t, 0.5, 3.0, 150.0, 5.0)
    >>> i.shape, bool(abs(i).max() <= 0.5)
    ((5000,), True)
    """
    return np.array([_signals.chirp(x, amplitude, w0, w1, duration) for x in t])


def filtered_random(t: np.ndarray, amplitude: float, cutoff: float, seed: int = 0) -> np.ndarray:
    """Low-passed Gaussian noise: white noise through a 4th-order Butterworth filter.

    Parameters
    ----------
    t : ndarray
        Step times (s), shape ``(N,)``; the filter takes each step as it comes.
    amplitude : float
        Root-mean-square current (A).
    cutoff : float
        Cut-off frequency of the filter (rad/s).
    seed : int
        Noise seed (the same seed, the same signal); an index.

    Returns
    -------
    ndarray
        Current held over each step (A), shape ``(N,)``.

    Examples
    --------
    >>> t = np.arange(0.0, 20.0, 1e-3)
    >>> i = arcosim.filtered_random(t, 0.5, 100.0, seed=1)
    >>> bool(0.3 < i.std() < 0.7)
    True
    """
    noise = _signals.FilteredNoise(amplitude, cutoff, seed)
    steps = np.diff(t, prepend=t[0] - (t[1] - t[0] if len(t) > 1 else 1e-3))
    return np.array([noise.next(float(h)) for h in steps])
