"""Scores of a load torque estimate against the torque the plant was given.

The estimate comes from :func:`arcosim.identification.load_torque.estimate_load_torque`
(the observer FMU's estimator run over a log); here it is compared with the truth of
the load scenario (:class:`arcosim.experiments.scenarios.LoadProfile`: a step, then a
sine). ``arcosim reproduce`` (experiment 5) and ``arcosim bench accuracy`` score with
:func:`score_profile`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from arcosim.experiments.scenarios import LoadProfile

#: A step counts as settled once the estimate stays within this fraction of its size.
SETTLED_WITHIN = 0.05


@dataclass(frozen=True)
class LoadScore:
    """How an estimate of the load scenario's torque compares with the truth.

    Attributes
    ----------
    size : float
        The step (N·m).
    settling_s : float
        Time from the step until the estimate stays within :data:`SETTLED_WITHIN` of
        the size up to the sine's start (s; NaN: never).
    settled_mean_percent : float
        Mean error over the step's settled window (% of the size).
    settled_max_percent : float
        Largest |error| over it (% of the size).
    settled_rms_percent : float
        Rms error over it (% of the size; the flexible motion's).
    sine_amplitude_ratio : float
        Amplitude of the estimate at the sine's frequency over the truth's
        (dimensionless; least-squares fits over the sine's window).
    sine_lag_s : float
        The estimate's lag behind the truth (s; phase difference / frequency).
    sine_rms_percent : float
        Rms error during the sine (% of the size).

    Examples
    --------
    >>> from arcosim.experiments import LoadProfile, score_profile
    >>> profile = LoadProfile(mass=1)
    >>> t = np.arange(0.0, profile.duration, 1e-3)
    >>> score = score_profile(t, profile.torque(t), profile)  # the truth as its estimate
    >>> score.settling_s, score.settled_mean_percent
    (0.0, 0.0)
    """

    size: float
    settling_s: float
    settled_mean_percent: float
    settled_max_percent: float
    settled_rms_percent: float
    sine_amplitude_ratio: float
    sine_lag_s: float
    sine_rms_percent: float

    def as_dict(self) -> dict[str, float]:
        """The scores by name (units as above)."""
        return asdict(self)


def score(
    time: np.ndarray,
    estimate: np.ndarray,
    truth: np.ndarray,
    step_time: float,
    sine_time: float,
    frequency: float,
    settled_from: float,
    sine_settled_from: float,
) -> LoadScore:
    """Score an estimate of a step then a sine (:class:`arcosim.experiments.scenarios.LoadProfile`).

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    estimate : ndarray
        Estimated torque at each sample (N·m), shape ``(N,)``.
    truth : ndarray
        The torque over the step ending at each sample (N·m), shape ``(N,)``.
    step_time, sine_time : float
        When the step and the sine start (s).
    frequency : float
        Of the sine (rad/s).
    settled_from : float
        Start of the step's settled window (s), before ``sine_time``.
    sine_settled_from : float
        Start of the sine's scoring window (s).

    Returns
    -------
    LoadScore
        Settling time (s), the settled errors and the sine's errors (% of the step's
        size), the sine's amplitude ratio and lag (s).
    """
    size = float(np.max(np.abs(truth)))
    error = estimate - truth
    step = (time >= step_time) & (time < sine_time)
    outside = np.nonzero(np.abs(error[step]) > SETTLED_WITHIN * size)[0]
    settling = math.nan
    if not len(outside) or outside[-1] + 1 < step.sum():
        last = time[step][outside[-1]] if len(outside) else step_time
        settling = float(last - step_time)
    settled = (time >= settled_from) & (time < sine_time)
    e = error[settled]
    sine = time >= sine_settled_from
    phase = frequency * (time[sine] - sine_time)
    basis = np.column_stack([np.sin(phase), np.cos(phase), np.ones(sine.sum())])
    fit = np.linalg.lstsq(basis, np.column_stack([estimate[sine], truth[sine]]), rcond=None)[0]
    (s, c), (s_true, c_true) = fit[:2, 0], fit[:2, 1]
    return LoadScore(
        size=size,
        settling_s=settling,
        settled_mean_percent=100.0 * float(np.mean(e)) / size,
        settled_max_percent=100.0 * float(np.max(np.abs(e))) / size,
        settled_rms_percent=100.0 * float(np.sqrt(np.mean(e**2))) / size,
        sine_amplitude_ratio=float(math.hypot(s, c) / math.hypot(s_true, c_true)),
        sine_lag_s=float(math.atan2(s, c) - math.atan2(s_true, c_true)) / frequency,
        sine_rms_percent=100.0 * float(np.sqrt(np.mean(error[sine] ** 2))) / size,
    )


def score_profile(time: np.ndarray, estimate: np.ndarray, profile: LoadProfile) -> LoadScore:
    """:func:`score` for a run of ``profile``.

    Parameters
    ----------
    time : ndarray
        Sample times of the run (s), shape ``(N,)``.
    estimate : ndarray
        Estimated torque at each sample (N·m), shape ``(N,)``.
    profile : LoadProfile
        The load the run was given (:class:`arcosim.experiments.scenarios.LoadProfile`).

    Returns
    -------
    LoadScore
        The scores (:func:`score`).

    Examples
    --------
    >>> from arcosim.experiments import LoadProfile
    >>> profile = LoadProfile(mass=1)
    >>> t = np.arange(0.0, profile.duration, 1e-3)
    >>> late = np.interp(t - 0.05, t, profile.torque(t))  # the truth, 50 ms late
    >>> round(score_profile(t, late, profile).sine_lag_s, 2)  # s
    0.05
    """
    truth = step_truth(time, profile.torque(time))
    return score(
        time,
        estimate,
        truth,
        profile.step_time,
        profile.sine_time,
        profile.frequency,
        profile.settled_from,
        profile.sine_from,
    )


def step_truth(time: np.ndarray, torque_at_start: Sequence[float]) -> np.ndarray:
    """The torque over the step ending at each sample, from the torque held over the
    step starting at each sample (the plant input's timing): shifted by one, 0 first.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    torque_at_start : sequence of float
        The torque held over the step starting at each sample (N·m), length N.

    Returns
    -------
    ndarray
        The torque over the step ending at each sample (N·m), shape ``(N,)``.
    """
    return np.concatenate([[0.0], np.asarray(torque_at_start, dtype=float)[:-1]])
