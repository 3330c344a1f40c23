"""Sensorless load torque offline: the observer FMU's estimator run over a log.

:func:`estimate_load_torque` runs :class:`arcosim.fmu.flexchain.observer.Observer` (the
same standard-library code the observer FMU bundles: DOB, reaction torque observer and
the load torque observer of :mod:`arcosim.fmu.flexchain.load_observer`) over a drive log,
one sample at a time, with the step each row takes. ``arcosim identify LOG.csv --method
load-torque`` is its command line; ``arcosim reproduce`` (experiment 5) and ``arcosim
bench accuracy`` score it (:mod:`arcosim.experiments.load_scores`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from arcosim.fmu.flexchain.observer import Observer, ObserverSettings
from arcosim.identification.errors import IdentificationError
from arcosim.identification.offline_observer import replay


@dataclass(frozen=True)
class LoadEstimate:
    """The estimator's outputs at every log row.

    Attributes
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    tau_load : ndarray
        Estimated torque on the load mass (N·m), shape ``(N,)``.
    tau_reac : ndarray
        The reaction torque observer's τ̂_reac (N·m), shape ``(N,)``.
    theta, omega : ndarray
        Estimated load angles (rad) and velocities (rad/s), shape ``(N, n)``.
    innovation : ndarray
        τ̂_reac minus the model's prediction (N·m), shape ``(N,)``.
    load_mass : int
        The mass the torque acts on, 1 … n (an index; 0: not said).
    load_torque_bandwidth : float
        The estimator's bandwidth for the load torque (rad/s; 0: not said).
    assumptions : dict of str to str
        What the estimate rests on, by topic (e.g. ``"defaults"``: the parameters left
        at the paper bench's value).

    Examples
    --------
    >>> t = np.arange(3) * 1e-3
    >>> z = np.zeros(3)
    >>> estimate = arcosim.LoadEstimate(t, t, z, z[:, None], z[:, None], z, load_mass=1)
    >>> report = estimate.to_json()
    >>> report["masses"], report["final"], report["mean_last_second"]
    (1, 0.002, 0.001)
    """

    time: np.ndarray
    tau_load: np.ndarray
    tau_reac: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    innovation: np.ndarray
    load_mass: int = 0
    load_torque_bandwidth: float = 0.0
    assumptions: dict[str, str] = field(default_factory=dict)

    def columns(self) -> dict[str, np.ndarray]:
        """CSV columns named as the observer FMU's outputs (``time`` first)."""
        n = self.theta.shape[1]
        columns = {"time": self.time, "tau_load_hat": self.tau_load, "tau_reac_hat": self.tau_reac}
        columns.update({f"theta_hat[{i + 1}]": self.theta[:, i] for i in range(n)})
        columns.update({f"omega_hat[{i + 1}]": self.omega[:, i] for i in range(n)})
        columns["innovation"] = self.innovation
        return columns

    def with_assumption(self, key: str, text: str) -> LoadEstimate:
        """The same estimate with one more assumption (``key``: a topic, ``text``: a
        sentence)."""
        return replace(self, assumptions={**self.assumptions, key: text})

    def to_json(self) -> dict[str, object]:
        """The summary as JSON data: ``method``, ``masses``, ``load_mass``,
        ``load_torque_bandwidth`` (rad/s), ``samples``, the ``final`` torque and its
        ``mean_last_second`` and ``std_last_second`` (N·m), ``rms_innovation`` (N·m) and,
        when any, ``assumptions``."""
        last = self.time >= self.time[-1] - 1.0
        report: dict[str, object] = {
            "method": "load-torque",
            "masses": self.theta.shape[1],
            "load_mass": self.load_mass,
            "load_torque_bandwidth": self.load_torque_bandwidth,
            "samples": len(self.time),
            "final": float(self.tau_load[-1]),
            "mean_last_second": float(np.mean(self.tau_load[last])),
            "std_last_second": float(np.std(self.tau_load[last])),
            "rms_innovation": float(np.sqrt(np.mean(self.innovation**2))),
        }
        if self.assumptions:
            report["assumptions"] = dict(self.assumptions)
        return report

    def text(self) -> str:
        """The summary as text: the final torque, the last second's mean and spread, the
        innovation, the assumptions."""
        report = self.to_json()
        lines = [
            f"{report['samples']} samples, load torque on mass {report['load_mass']} of "
            f"{report['masses']} (bandwidth {report['load_torque_bandwidth']:g} rad/s):",
            f"  final              {report['final']:.6g} N·m",
            f"  last second        {report['mean_last_second']:.6g} ± "
            f"{report['std_last_second']:.2g} N·m (mean ± std)",
            f"  rms innovation     {report['rms_innovation']:.3g} N·m",
        ]
        lines += [f"  assumption, {key}: {text}" for key, text in self.assumptions.items()]
        return "\n".join(lines)


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
        τ̂_reac (N·m), the load angles (rad) and velocities (rad/s), the innovation;
        its summary (:meth:`LoadEstimate.to_json`, :meth:`LoadEstimate.text`).

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
    if not (settings.model_based and 1 <= settings.load_mass <= len(settings.J)):
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
    return LoadEstimate(
        t.copy(),
        tau_load,
        tau_reac,
        theta,
        omega,
        innovation,
        settings.load_mass,
        settings.load_torque_bandwidth,
    )
