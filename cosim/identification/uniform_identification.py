"""The paper's uniform chain identified from a log: one k and one B for every spring (and a
common scale on the known J_i), by output error, with its report.

:func:`identify_uniform_chain` is the output-error method's whole job (what ``arcosim
identify LOG --method output-error`` runs): it builds the reaction-torque record
(:func:`~arcosim.identification.records.record.motor_record`), refuses a start stiffness
the record cannot show, runs :func:`~arcosim.identification.fit.uniform_fit.uniform_chain`
and returns a :class:`UniformChainIdentification` with its report
(:meth:`~UniformChainIdentification.to_json`, :meth:`~UniformChainIdentification.text`)
and its chain (``.chain``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from arcosim.fmu.flexchain.chain import Chain
from arcosim.fmu.flexchain.defaults import G_DIST
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.output_error import ParameterFit
from arcosim.identification.fit.uniform_fit import clamped_frequencies, uniform_chain
from arcosim.identification.records.record import MotorRecord, motor_record

#: The report's names of the fit's parameters.
REPORT_NAMES = {"k": "k_hat", "B": "B_hat", "J_scale": "J_scale"}


@dataclass(frozen=True)
class UniformChainIdentification:
    """The uniform chain fitted to a log, and what the fit rests on.

    Attributes
    ----------
    fit : ParameterFit
        ``k`` (N·m/rad), ``B`` (N·m·s/rad) and, when fitted, ``J_scale``
        (dimensionless), with their standard errors (Newey–West) and the evidence.
    J : tuple of float
        The known load inertias J_1 … J_n (kg·m²), shape ``(n,)``, before any scale.
    samples : int
        Rows of the log (a count).
    velocity : str
        Where the record's velocity came from (a sentence).
    duration : float
        The record's length (s).
    assumptions : dict of str to str
        What the result rests on, by topic (e.g. ``"defaults"``: the parameters left at
        the paper bench's value).

    Examples
    --------
    >>> import dataclasses
    >>> run = arcosim.run_scenario(dataclasses.replace(arcosim.SCENARIOS["flexible"], duration=5.0))
    >>> signals = [run[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")]
    >>> motor = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406, D_m=2e-5, f_c=2e-3)
    >>> J = [5.15299e-4, 5.15299e-4, 6.192707e-4]
    >>> found = arcosim.identify_uniform_chain(run.time, *signals, motor, J)
    >>> bool(abs(found.chain.k[0] / 0.1627 - 1.0) < 0.01)  # the bench's k, within 1 %
    True
    """

    fit: ParameterFit
    J: tuple[float, ...]
    samples: int
    velocity: str
    duration: float
    assumptions: dict[str, str] = field(default_factory=dict)

    @property
    def chain(self) -> Chain:
        """The fitted chain: every k_i = k̂ (N·m/rad), B_i = B̂ (N·m·s/rad), J_i as given
        (kg·m², times ``J_scale`` when fitted), with the fit's standard errors."""
        values, std = self.fit.as_dict(), self.fit.std_dict()
        n, scale = len(self.J), values.get("J_scale", 1.0)
        J_std = tuple(std["J_scale"] * x for x in self.J) if "J_scale" in std else ()
        return Chain(
            J=tuple(scale * x for x in self.J),
            k=(values["k"],) * n,
            B=(values["B"],) * n,
            J_std=J_std,
            k_std=(std["k"],) * n,
            B_std=(std["B"],) * n,
        )

    def with_assumption(self, key: str, text: str) -> UniformChainIdentification:
        """The same result with one more assumption (``key``: a topic, ``text``: a
        sentence)."""
        return replace(self, assumptions={**self.assumptions, key: text})

    def to_json(self) -> dict[str, object]:
        """The report as JSON data: ``k_hat``, ``B_hat`` (and ``J_scale``), ``std``, the
        evidence (``method``, ``start``, ``velocity``, ``rms_residual`` and ``rms_data``
        N·m, ``newey_west_lag`` samples, ``duration`` s, ``evaluations``) and, when any,
        ``assumptions``."""
        fit = self.fit
        report: dict[str, object] = {REPORT_NAMES[k]: v for k, v in fit.as_dict().items()}
        report["std"] = {REPORT_NAMES[k]: v for k, v in fit.std_dict().items()}
        report.update(
            {
                "method": "output-error",
                "start": fit.start_note,
                "velocity": self.velocity,
                "rms_residual": fit.rms_residual,
                "rms_data": fit.rms_data,
                "newey_west_lag": fit.lag,
                "duration": self.duration,
                "evaluations": fit.evaluations,
            }
        )
        if self.assumptions:
            report["assumptions"] = dict(self.assumptions)
        return report

    def text(self) -> str:
        """The report as text: the estimates with their standard errors, the evidence,
        the assumptions."""
        report = self.to_json()
        lines = [
            f"{self.samples} samples, output-error fit of the uniform chain ({len(self.J)} masses):"
        ]
        for key in (k for k in report if k in REPORT_NAMES.values()):
            lines.append(f"  {key:8s} {report[key]:.6g}  ± {report['std'][key]:.2g}")
        for key in ("start", "velocity", "rms_residual", "rms_data", "newey_west_lag"):
            lines.append(f"  {key}: {report[key]}")
        lines += [f"  assumption, {key}: {text}" for key, text in self.assumptions.items()]
        return "\n".join(lines)


def identify_uniform_chain(
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta_m: np.ndarray,
    actuator: Actuator,
    J: Sequence[float],
    *,
    g_dist: float = G_DIST,
    fit_inertia_scale: bool = False,
    k_start: float | None = None,
) -> UniformChainIdentification:
    """Fit the paper's uniform chain to a log by output error: one k and one B for every
    spring, the load inertias known.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``, a constant step.
    i_a : ndarray
        Current (A), shape ``(N,)``.
    omega_m : ndarray
        Motor velocity (rad/s), shape ``(N,)``.
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.
    actuator : Actuator
        The motor's terms (J_mo kg·m², k_to N·m/A, friction).
    J : sequence of float
        The known load inertias J_1 … J_n (kg·m²), each > 0.
    g_dist : float
        Bandwidth of the disturbance observer (rad/s).
    fit_inertia_scale : bool
        Also fit one common scale on the J_i (dimensionless).
    k_start : float, optional
        Start from this stiffness (N·m/rad) instead of the cost scan.

    Returns
    -------
    UniformChainIdentification
        The fit, its chain, its report.

    Raises
    ------
    IdentificationError
        A load inertia not > 0, a ``k_start`` whose chain's first mode the record cannot
        show, a record with no motion or no reaction torque.

    Examples
    --------
    >>> import dataclasses
    >>> run = arcosim.run_scenario(dataclasses.replace(arcosim.SCENARIOS["flexible"], duration=5.0))
    >>> signals = [run[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")]
    >>> motor = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406, D_m=2e-5, f_c=2e-3)
    >>> J = [5.15299e-4, 5.15299e-4, 6.192707e-4]
    >>> found = arcosim.identify_uniform_chain(run.time, *signals, motor, J)
    >>> sorted(found.to_json())[:3]
    ['B_hat', 'duration', 'evaluations']
    """
    J = [float(x) for x in J]
    if any(not x > 0 for x in J):
        raise IdentificationError(f"the load inertias must be > 0, got J = {J}")
    record = motor_record(time, i_a, omega_m, theta_m, actuator, g_dist)
    if k_start is not None:
        check_start_k(k_start, J, record)
    result = uniform_chain(record, J, fit_inertia_scale, k_start)
    return UniformChainIdentification(
        result, tuple(J), len(time), record.velocity_source, record.duration
    )


def check_start_k(k: float, J: Sequence[float], record: MotorRecord) -> None:
    """Refuse a start stiffness whose chain's first mode the record cannot show.

    Parameters
    ----------
    k : float
        The start stiffness (N·m/rad).
    J : sequence of float
        The load inertias (kg·m²), shape ``(n,)``.
    record : MotorRecord
        The record the fit runs on (its length and step).

    Raises
    ------
    IdentificationError
        When the uniform chain's first clamped mode lies outside the band from one
        period in the record's length to the Nyquist frequency π/h.
    """
    unit = float(clamped_frequencies([float(x) for x in J], [1.0] * len(J))[0])
    low_w, high_w = 2.0 * math.pi / record.duration, math.pi / record.h
    low, high = (low_w / unit) ** 2, (high_w / unit) ** 2
    if not low <= k <= high:
        raise IdentificationError(
            f"--start-k {k:g}: give a stiffness from {low:.3g} to {high:.3g} N.m/rad for this "
            f"log and J (the chain's first mode between one period in {record.duration:g} s, "
            f"{low_w:.3g} rad/s, and the Nyquist frequency, {high_w:.3g} rad/s)"
        )
