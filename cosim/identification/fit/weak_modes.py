"""The chain without the weakly determined modes it keeps: is its residual still at the
noise floor? (offline)

``masses="auto"`` may keep a mode whose residue is under
:data:`~arcosim.identification.fit.refusal.T_CONFIRM` standard errors when the
information criterion prefers it. Such a mode may be real, or take up a misfit: a k_t
given 10 % high puts 0.1·J_m·α into τ̂ (an inertia on the motor, beyond any spring),
which an extra mode above the others fits, and the residual falls to the floor. The
fit without those modes (:func:`without_weak_modes`) is held against the floor by
:func:`~arcosim.identification.drive_identification.identify_drive`
(:func:`~arcosim.identification.checks.noise_floor.weak_mode_floor_warning`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.output_error import ParameterFit
from arcosim.identification.fit.refusal import T_CONFIRM
from arcosim.identification.modes.detection import DetectedModes


def weak_kept(detected: DetectedModes, n: int) -> list[float]:
    """The weakly determined modes (residue t under :data:`T_CONFIRM`) among the ``n``
    strongest the record shows (rad/s).

    Parameters
    ----------
    detected : DetectedModes
        The modes the record shows.
    n : int
        The number of masses chosen (a count): the n modes with the largest t.

    Returns
    -------
    list of float
        Their frequencies (rad/s), ascending; empty when every kept mode is confirmed.
    """
    keep = np.argsort(-np.asarray(detected.t_value, dtype=float))[:n]
    return sorted(float(detected.frequency[i]) for i in keep if detected.t_value[i] < T_CONFIRM)


def without_weak_modes(
    detected: DetectedModes, n: int, fit: Callable[[int], ParameterFit] | None
) -> ParameterFit | None:
    """The fit without the weakly determined modes the n-mass chain keeps.

    Parameters
    ----------
    detected : DetectedModes
        The modes the record shows.
    n : int
        The number of masses chosen (a count).
    fit : callable or None
        ``fit(m)``: the fit of the m strongest modes (m = 0: the rigid drive); None:
        no fit (without the encoder's record).

    Returns
    -------
    ParameterFit or None
        That fit, the modes it leaves out in ``extra["dropped_weak_modes_rad_s"]``
        (rad/s); None when the chain keeps no weak mode, ``fit`` is None, or the
        leaner chain does not fit.
    """
    dropped = weak_kept(detected, n) if n >= 1 and fit is not None else []
    if not dropped:
        return None
    try:
        leaner = fit(n - len(dropped))
    except (IdentificationError, ValueError, np.linalg.LinAlgError):
        return None
    leaner.extra["dropped_weak_modes_rad_s"] = dropped
    return leaner
