"""The band a drive log can show the chain's modes in (rad/s): the one home of that rule.

Two limits bound it. The disturbance observer's ``G(s) = g / (s + g)`` still passes a
third of the reaction torque at :data:`BAND_PER_G` · g_dist (:func:`dob_band`), and the
sample step h leaves :data:`SAMPLE_BAND` / h (:func:`sample_band`: about a twentieth of
the sampling frequency, where a held step still follows a sine). The modes are sought
below the lower of the two, min(3·g_dist, 0.3/h) (:func:`search_band`); the
excitation's lines are checked against each.
"""

from __future__ import annotations

#: Highest clamped frequency sought, in units of g_dist (dimensionless).
BAND_PER_G = 3.0
#: Highest frequency the sample step leaves, times the step (rad per step).
SAMPLE_BAND = 0.3


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
