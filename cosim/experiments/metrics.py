"""How estimates are scored against the plant's truth (docs/method.md)."""

from __future__ import annotations

import numpy as np


def flexible_score(estimate: np.ndarray, truth: np.ndarray, motor: np.ndarray) -> float:
    """State score of one mass: rms(θ̂_i − θ_i) / rms(θ_i − θ_m).

    The error relative to the flexible part of the motion (the rigid part is easy and
    would hide errors); 0 is perfect, the naive ``θ̂_i = θ_m`` scores 1.

    Parameters
    ----------
    estimate, truth : ndarray
        The estimated and the true angle of the mass (rad), shape ``(N,)``.
    motor : ndarray
        The true motor angle (rad), shape ``(N,)``.

    Returns
    -------
    float
        The score (dimensionless).

    Examples
    --------
    >>> motor = np.zeros(4)
    >>> truth = np.array([1.0, -1.0, 1.0, -1.0])
    >>> flexible_score(motor, truth, motor)
    1.0
    """
    flexible = max(float(np.mean((truth - motor) ** 2)), 1e-300)
    return float(np.sqrt(np.mean((estimate - truth) ** 2) / flexible))


def percent_error(estimate: float, truth: float) -> float:
    """Relative error of ``estimate`` in percent of ``truth`` (both in one unit).

    Parameters
    ----------
    estimate : float
        The estimate (any unit).
    truth : float
        The true value (in the unit of ``estimate``), ≠ 0.

    Returns
    -------
    float
        ``100 (estimate / truth − 1)`` (%).

    Examples
    --------
    >>> round(percent_error(1.01, 1.0), 6)
    1.0
    """
    return 100.0 * (estimate / truth - 1.0)
