"""Sensorless load torque offline: the observer FMU's estimator run over a log, and the
scores of an estimate against a known torque.

:func:`estimate` runs :class:`arcosim.fmu.flexchain.observer.Observer` (the same standard-library
code the observer FMU bundles: DOB, reaction torque observer and the load torque
observer of :mod:`arcosim.fmu.flexchain.load_observer`) over a drive log, one sample at a time,
with the step each row takes. ``arcosim identify LOG.csv --method load-torque`` is its
command line; ``arcosim reproduce`` (experiment 5) and ``arcosim bench accuracy`` score
it with :func:`score`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np

from arcosim.fmu.flexchain.observer import MODEL_BASED, STATE_ESTIMATION, Observer, ObserverSettings
from arcosim.identification.errors import IdentificationError
from arcosim.identification.offline_observer import replay

#: A step counts as settled once the estimate stays within this fraction of its size.
SETTLED_WITHIN = 0.05


@dataclass(frozen=True)
class LoadEstimate:
    """The estimator's outputs at every log row.

    Attributes:
        time: s, shape (N,).
        tau_load: estimated torque on the load mass (N·m), (N,).
        tau_reac: the reaction torque observer's τ̂_reac (N·m), (N,).
        theta, omega: estimated load angles (rad) and velocities (rad/s), (N, n).
        innovation: τ̂_reac minus the model's prediction (N·m), (N,).
    """

    time: np.ndarray
    tau_load: np.ndarray
    tau_reac: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    innovation: np.ndarray

    def columns(self) -> dict[str, np.ndarray]:
        """CSV columns named as the observer FMU's outputs (``time`` first)."""
        n = self.theta.shape[1]
        columns = {"time": self.time, "tau_load_hat": self.tau_load, "tau_reac_hat": self.tau_reac}
        columns.update({f"theta_hat[{i + 1}]": self.theta[:, i] for i in range(n)})
        columns.update({f"omega_hat[{i + 1}]": self.omega[:, i] for i in range(n)})
        columns["innovation"] = self.innovation
        return columns


def estimate_load_torque(
    settings: ObserverSettings,
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta_m: np.ndarray,
) -> LoadEstimate:
    """The torque on a load mass over a recorded log, from the motor's signals alone.

    The observer FMU's own estimator (mode 2, estimator 1 with ``load_mass``), run
    offline one sample at a time with the step each row takes.

    Parameters
    ----------
    settings : ObserverSettings
        Mode 2, estimator 1, ``load_mass`` ≥ 1, the chain (J_i kg·m², k_i N·m/rad,
        B_i N·m·s/rad) and the actuator, as the observer FMU's parameters would say.
    time : ndarray
        Sample times (s), strictly increasing, shape ``(N,)``.
    i_a : ndarray
        Current (A), shape ``(N,)``.
    omega_m : ndarray
        Motor velocity (rad/s), shape ``(N,)``.
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.

    Returns
    -------
    LoadEstimate
        The estimated torque on the load mass (N·m, the plant's ``tau_ext`` sign),
        τ̂_reac (N·m), the load angles (rad) and velocities (rad/s), the innovation.

    Raises
    ------
    IdentificationError
        For settings that do not estimate a load torque.

    Examples
    --------
    >>> import dataclasses
    >>> from arcosim.fmu.flexchain import defaults
    >>> run = arcosim.run_scenario(dataclasses.replace(arcosim.SCENARIOS["flexible"], duration=2.0))
    >>> settings = arcosim.ObserverSettings(
    ...     mode=2, actuator=arcosim.Actuator(defaults.J_M, defaults.K_T, D_m=2e-5, f_c=2e-3),
    ...     g_dist=100.0, g_lpf=100.0, J=defaults.J, k=(defaults.K,) * 3, B=(defaults.B,) * 3,
    ...     estimator=1, encoder_cpr=2000, load_mass=3)
    >>> signals = [run[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")]
    >>> estimate = arcosim.estimate_load_torque(settings, run.time, *signals)
    >>> estimate.tau_load.shape, bool(abs(estimate.tau_load[-1]) < 1e-3)  # no load: ≈ 0 N·m
    ((2001,), True)
    """
    if not (
        settings.mode == STATE_ESTIMATION
        and settings.estimator == MODEL_BASED
        and 1 <= settings.load_mass <= len(settings.J)
    ):
        raise IdentificationError(
            f"the load torque estimator needs mode 2, estimator 1 and a load mass 1 … "
            f"{len(settings.J)}, got mode {settings.mode}, estimator {settings.estimator}, "
            f"load_mass {settings.load_mass}"
        )
    t = np.asarray(time, dtype=float)
    count, n = len(t), len(settings.J)
    tau_load, tau_reac, innovation = np.zeros(count), np.zeros(count), np.zeros(count)
    theta, omega = np.empty((count, n)), np.empty((count, n))

    def keep(k: int, observer: Observer) -> None:
        est = observer.estimator
        theta[k], omega[k] = est.theta, est.omega
        if k:
            tau_load[k], tau_reac[k] = est.tau_load, observer.dob.tau_reac_hat
            innovation[k] = est.innovation

    replay(settings, {"time": t, "i_a": i_a, "omega_m": omega_m, "theta_m": theta_m}, keep)
    return LoadEstimate(t.copy(), tau_load, tau_reac, theta, omega, innovation)


@dataclass(frozen=True)
class LoadScore:
    """How an estimate of the load scenario's torque compares with the truth.

    Attributes:
        size: the step (N·m).
        settling_s: time from the step until the estimate stays within
            :data:`SETTLED_WITHIN` of the size up to the sine's start (s; NaN: never).
        settled_mean_percent: mean error over the step's settled window, % of the size.
        settled_max_percent: largest |error| over it, % of the size.
        settled_rms_percent: rms error over it, % of the size (the flexible motion's).
        sine_amplitude_ratio: amplitude of the estimate at the sine's frequency over the
            truth's (least-squares fits over the sine's window).
        sine_lag_s: the estimate's lag behind the truth (phase difference / frequency, s).
        sine_rms_percent: rms error during the sine, % of the size.
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

    Args:
        time: sample times (s), (N,).
        estimate: estimated torque at each sample (N·m), (N,).
        truth: the torque over the step ending at each sample (N·m), (N,).
        step_time, sine_time: when the step and the sine start (s).
        frequency: of the sine (rad/s).
        settled_from: start of the step's settled window (s), before ``sine_time``.
        sine_settled_from: start of the sine's scoring window (s).
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


def score_profile(time: np.ndarray, estimate: np.ndarray, profile) -> LoadScore:
    """:func:`score` for a run of ``profile`` (a
    :class:`arcosim.experiments.scenarios.LoadProfile`)."""
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
    step starting at each sample (the plant input's timing): shifted by one, 0 first."""
    return np.concatenate([[0.0], np.asarray(torque_at_start, dtype=float)[:-1]])
