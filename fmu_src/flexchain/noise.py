"""Reproducible noise and the encoder model, for the plant's sensors and the
excitation source.

The noise is counter-based (a hash of seed and sample number), so sample k is the
same whatever happened before it: runs are reproducible for a seed, saving and
restoring an FMU's state needs only the counter, and a C port gives the same bits.
"""

from __future__ import annotations

import math

_MASK = (1 << 64) - 1


def _splitmix64(z: int) -> int:
    z = (z + 0x9E3779B97F4A7C15) & _MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK
    return z ^ (z >> 31)


def uniform(seed: int, k: int) -> float:
    """Uniform sample number ``k`` of stream ``seed``.

    Parameters
    ----------
    seed : int
        Stream identifier (any integer).
    k : int
        Sample number (a count, ≥ 0).

    Returns
    -------
    float
        A sample in [0, 1) (dimensionless), 53 random bits.
    """
    base = _splitmix64((seed & _MASK) ^ 0x2545F4914F6CDD1D)
    return (_splitmix64((base + k) & _MASK) >> 11) * 2.0**-53


def gaussian(seed: int, k: int) -> float:
    """Standard normal sample number ``k`` of stream ``seed`` (Box–Muller).

    Parameters
    ----------
    seed : int
        Stream identifier (any integer).
    k : int
        Sample number (a count, ≥ 0).

    Returns
    -------
    float
        A sample of the standard normal distribution (dimensionless).

    Examples
    --------
    >>> gaussian(1, 0) == gaussian(1, 0), gaussian(1, 0) == gaussian(2, 0)  # reproducible
    (True, False)
    """
    base = _splitmix64((seed & _MASK) ^ 0x5DEECE66D)
    a = _splitmix64((base + 2 * k) & _MASK)
    b = _splitmix64((base + 2 * k + 1) & _MASK)
    u1 = ((a >> 11) + 1) * 2.0**-53  # (0, 1]
    u2 = (b >> 11) * 2.0**-53  # [0, 1)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(2.0 * math.pi * u2)


def quantize(theta: float, counts_per_rev: int) -> float:
    """The angle as an incremental encoder reports it: whole counts, floored.

    Parameters
    ----------
    theta : float
        True angle (rad) relative to the angle at start.
    counts_per_rev : int
        Counts per revolution after quadrature (a count); 0 = ideal encoder.

    Returns
    -------
    float
        The reported angle (rad).

    Examples
    --------
    >>> count = 2 * math.pi / 2000  # one count of a 2000-count encoder (rad)
    >>> quantize(0.5 * count, 2000), quantize(1.5 * count, 2000) == count, quantize(0.3, 0)
    (0.0, True, 0.3)
    """
    if counts_per_rev <= 0:
        return theta
    step = 2.0 * math.pi / counts_per_rev
    return math.floor(theta / step) * step
