"""Lines that are harmonics of one fundamental: a periodic reference (offline).

A square-wave or stepped reference (position-loop steps) puts its power on whole
multiples of one fundamental ω_0; :func:`harmonic_fundamental` finds ω_0 from the lines
:mod:`arcosim.identification.excitation.spectrum` found, so the excitation is read as one period's
harmonics, not as many unrelated lines.
"""

from __future__ import annotations

import numpy as np

#: Periodic: the lowest line must be at most this harmonic of the fundamental (a count).
FIRST_HARMONIC = 3
#: Periodic: at least this many lines (a count) on multiples of one fundamental.
LEAST_HARMONICS = 3
#: Periodic: the harmonics present fill at least this share of the multiples up to the
#: highest (dimensionless): a square wave's odd ones about half, a multi-sine whose few
#: lines happen to sit on whole rad/s (10 of 120) far fewer.
HARMONIC_FILL = 0.25
#: Periodic: the harmonics carry at least this share of the lines' power
#: (dimensionless, 0 … 1).
HARMONIC_POWER = 0.8
#: Periodic: a line is a harmonic when within this many frequency bins (2π/T) of k·ω_0.
HARMONIC_TOLERANCE = 0.5


def harmonic_fundamental(
    lines: np.ndarray, resolution: float, amplitudes: np.ndarray | None = None
) -> float:
    """The fundamental (rad/s) the lines are harmonics of, or 0 when they are not.

    The lines count as harmonics of ω_0 when at least :data:`LEAST_HARMONICS` of them
    sit within :data:`HARMONIC_TOLERANCE` bins (``resolution``) of whole multiples
    k·ω_0, the lowest of those at most the :data:`FIRST_HARMONIC`-th, they fill
    :data:`HARMONIC_FILL` of the multiples up to the highest, and they carry
    :data:`HARMONIC_POWER` of the lines' power: a square-wave or stepped reference (in
    a closed loop its current also shows the loop's resonances between the harmonics),
    not a multi-sine whose lines merely lie on the record's grid (its lowest line the
    10th or the 100th multiple of 2π/T).

    Parameters
    ----------
    lines : ndarray
        Line frequencies (rad/s), ascending, shape ``(L,)``.
    resolution : float
        The record's frequency grid 2π/T (rad/s).
    amplitudes : ndarray, optional
        The lines' amplitudes (any unit), shape ``(L,)``; default all equal.

    Returns
    -------
    float
        ω_0 (rad/s), fitted by least squares over the harmonics; 0 when the lines are
        not harmonics of one fundamental.

    Examples
    --------
    >>> round(harmonic_fundamental(np.array([2.0, 6.01, 10.0, 14.02]), 0.1), 3)
    2.002
    >>> harmonic_fundamental(np.geomspace(3.0, 150.0, 40), 0.1)
    0.0
    """
    if len(lines) < LEAST_HARMONICS:
        return 0.0
    power = np.ones(len(lines)) if amplitudes is None else np.asarray(amplitudes) ** 2
    strongest = lines[int(np.argmax(power))]
    for base in dict.fromkeys((lines[0], strongest)):
        for first in range(1, FIRST_HARMONIC + 1):
            w0 = _harmonic_fit(lines, base / first, resolution)
            if w0 >= resolution:
                on = on_harmonics(lines, w0, resolution)
                lowest = lines[on][0] / w0 if np.any(on) else np.inf
                count = int(np.sum(on))
                top = np.rint(lines[on][-1] / w0) if count else np.inf
                enough = count >= LEAST_HARMONICS and lowest < FIRST_HARMONIC + 0.5
                enough = enough and count >= HARMONIC_FILL * top
                if enough and power[on].sum() >= HARMONIC_POWER * power.sum():
                    return w0
    return 0.0


def on_harmonics(lines: np.ndarray, w0: float, resolution: float) -> np.ndarray:
    """Which ``lines`` (rad/s, shape ``(L,)``) lie within :data:`HARMONIC_TOLERANCE` bins
    (``resolution``, rad/s) of a multiple k ≥ 1 of ``w0`` (rad/s); boolean, shape ``(L,)``."""
    k = np.rint(lines / w0)
    return (k >= 1) & (np.abs(lines - k * w0) <= HARMONIC_TOLERANCE * resolution + 1e-3 * lines)


def _harmonic_fit(lines: np.ndarray, w0: float, resolution: float) -> float:
    """ω_0 (rad/s) refitted by least squares on the lines near its multiples."""
    for _ in range(3):
        on = on_harmonics(lines, w0, resolution)
        if not np.any(on):
            return w0
        k = np.rint(lines[on] / w0)
        w0 = float(np.sum(k * lines[on]) / np.sum(k * k))
    return w0
