"""The whole job on a flexible link from its hub's log: EI, ρA (unless given) and the
damping, or the modal model without the link's length; the report, and the tip's motion
over the log (offline).

:func:`identify_link` is to a link what
:func:`~arcosim.identification.drive_identification.identify_drive` is to a chain: it
checks the log's plausibility, builds the two records, runs
:func:`~arcosim.identification.link.beam_fit.fit_link` (or
:func:`~arcosim.identification.link.beam_fit.fit_modes`), checks the residual against
the noise floor, and returns a :class:`LinkIdentification` with its report
(:meth:`LinkIdentification.to_json`, :meth:`LinkIdentification.text`), its equivalent
lumped chain (``.chain``, what ``--chain`` reads) and the tip's motion on demand.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from arcosim.fmu.flexchain.chain import Chain
from arcosim.fmu.flexchain.defaults import G_DIST
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.checks.log_check import log_plausibility
from arcosim.identification.checks.noise_floor import floor_warning, noise_floor
from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.motor_friction import without_friction
from arcosim.identification.fit.output_error import ParameterFit, predict
from arcosim.identification.link.beam_fit import Geometry, fit_link, fit_modes, modal_of
from arcosim.identification.link.beam_model import ModalModel, observer_parameters
from arcosim.identification.link.beam_motion import (
    TipMotion,
    link_assumptions,
    stiffening_warning,
    tip_motion,
)
from arcosim.identification.records.record import EncoderRecord, encoder_record, motor_record


@dataclass(frozen=True)
class LinkIdentification:
    """A flexible link identified from its hub: the fit, the modal model, the report.

    Attributes
    ----------
    fit : ParameterFit
        EI (N·m²), ρA (kg/m, unless given) and the damping, or the modal model's
        parameters without a geometry, with standard errors.
    model : ModalModel
        The link's clamped modes seen from the hub.
    geometry : Geometry or None
        What the user knows of the link; None: the modal model only.
    D_m, f_c : float
        The hub's viscous (N·m·s/rad) and Coulomb (N·m) friction, fitted or given.
    assumptions : dict of str to str
        What the result rests on, by topic.
    warnings : list of str
        The log's plausibility, the fit's and the noise floor's warnings.
    rms_residual : float
        RMS of τ̂_reac's residual against the model (N·m).
    duration : float
        The record's length (s).
    encoder : EncoderRecord
        The current → encoder record the fit read (for the tip's motion).
    """

    #: Units of the tip's motion over the log (:meth:`tip_columns`).
    TIP_UNITS: ClassVar[dict[str, str]] = {
        "time": "s",
        "alpha_tip_hat": "rad",
        "w_tip_hat": "m",
        "tau_reac_hat": "N.m",
    }

    fit: ParameterFit
    model: ModalModel
    geometry: Geometry | None
    D_m: float
    f_c: float
    assumptions: dict[str, str]
    warnings: list[str]
    rms_residual: float
    duration: float
    encoder: EncoderRecord = field(repr=False)

    @property
    def chain(self) -> Chain:
        """The equivalent lumped chain and the hub's friction, as ``--chain`` reads the
        report (:func:`~arcosim.chainfile.read_chain`)."""
        values = {**self.fit.extra["chain"], "D_m": self.D_m, "f_c": self.f_c}
        return Chain.from_parameters(values, n=int(values["masses"]))

    def with_assumption(self, key: str, text: str) -> LinkIdentification:
        """This result with one more assumption ``key``: ``text`` (e.g. the defaults)."""
        return replace(self, assumptions={**self.assumptions, key: text})

    def tip_motion(self) -> TipMotion:
        """The tip's deflection and the reaction torque over the log (rad, m, N·m)."""
        return tip_motion(self.encoder, self.model, self.D_m, self.f_c)

    def tip_columns(self, time: np.ndarray) -> dict[str, np.ndarray]:
        """The tip's motion as columns (:data:`TIP_UNITS`) over the log's ``time`` (s)."""
        tip = self.tip_motion()
        return {
            "time": time,
            "alpha_tip_hat": tip.alpha_tip,
            "w_tip_hat": tip.w_tip,
            "tau_reac_hat": tip.tau_reac,
        }

    def to_json(self) -> dict[str, object]:
        """Everything, JSON-able: the fit, the modal model, the equivalent chain (also at
        the top, as ``--chain`` reads it), assumptions and warnings."""
        result, model, geometry = self.fit, self.model, self.geometry
        extra = result.extra
        chain = extra["chain"]
        out: dict[str, object] = {"method": "beam"}
        out.update(result.as_dict())
        out["std"] = result.std_dict()
        out.update(
            modes_rad_s=[float(w) for w in model.frequency],
            damping_ratios=[float(z) for z in model.damping],
            participation=[float(b) for b in model.participation],
            J_link=float(model.J_link),
            J_rest=float(model.J_rest),
        )
        if geometry is not None:
            rhoA = extra.get("rhoA_given")
            if rhoA is not None:  # given, held: a value without a standard error
                out.update(rhoA=rhoA, rhoA_given=True)
            out.update(
                L=geometry.L,
                m_tip=geometry.m_tip,
                J_tip=geometry.J_tip,
                r_hub=geometry.r_hub,
                tip_shape_m=[float(p) for p in model.tip],
                observer_parameters=observer_parameters(model),
            )
        out.update(
            equivalent_chain=dict(chain),
            start=result.start_note,
            rms_innovation=result.rms_residual,
            rms_residual=self.rms_residual,
            newey_west_lag=result.lag,
            duration=self.duration,
            evaluations=result.evaluations,
            detected_modes_rad_s=extra.get("detected_modes_rad_s", extra.get("modes_rad_s")),
            assumptions=self.assumptions,
            warnings=self.warnings,
        )
        out.update(chain)  # J[i], k[i], B[i], masses: what --chain reads
        out.update(D_m=self.D_m, f_c=self.f_c)
        return out

    def text(self, samples: int) -> str:
        """The report as text, for a log of ``samples`` samples."""
        report = self.to_json()
        lines = [f"{samples} samples, flexible link ({report['method']}):"]
        for key, value in report["std"].items():
            lines.append(f"  {key:9s} {report[key]:.6g}  ± {value:.2g}")
        for key in ("modes_rad_s", "damping_ratios", "participation", "J_link", "start"):
            lines.append(f"  {key}: {report[key]}")
        for key, text in self.assumptions.items():
            lines.append(f"  assumption, {key}: {text}")
        for text in self.warnings:
            lines.append(f"  warning: {text}")
        chain = report["equivalent_chain"]
        values = " ".join(f"{k}={v:.4g}" for k, v in chain.items() if k != "masses")
        lines.append(f"  equivalent chain ({chain['masses']} masses, --chain reads it): {values}")
        return "\n".join(lines)


def identify_link(
    time: Sequence[float] | np.ndarray,
    i_a: Sequence[float] | np.ndarray,
    omega_m: Sequence[float] | np.ndarray,
    theta_m: Sequence[float] | np.ndarray,
    actuator: Actuator,
    *,
    encoder_cpr: int,
    fit_friction: bool = True,
    L: float | None = None,
    m_tip: float = 0.0,
    J_tip: float = 0.0,
    r_hub: float = 0.0,
    rhoA: float | None = None,
    g_dist: float = G_DIST,
) -> LinkIdentification:
    """A flexible link on a hub identified from the hub's current and encoder.

    Parameters
    ----------
    time, i_a, omega_m, theta_m : array_like
        Sample times (s, a constant step), motor current (A), velocity (rad/s) and
        angle (rad, whole encoder counts), shape ``(N,)`` each.
    actuator : Actuator
        The motor's terms (J_mo, k_to, Δk_t, ΔJ; D_m and f_c used only when
        ``fit_friction`` is False).
    encoder_cpr : int
        The encoder's counts per revolution (a count), > 0.
    fit_friction : bool
        Fit the hub's D_m and f_c with the link (True), or take the actuator's.
    L : float or None
        The link's length (m), > 0; None: fit the modal model only (no EI, ρA or tip
        shape).
    m_tip, J_tip, r_hub : float
        The tip's mass (kg) and inertia (kg·m²), the clamp's radius (m), ≥ 0 (with ``L``).
    rhoA : float or None
        The link's mass per length (kg/m), held in the fit (EI from one clamped mode);
        None: fitted (two clamped modes needed).
    g_dist : float
        The DOB's bandwidth (rad/s).

    Returns
    -------
    LinkIdentification
        The fit, the modal model and the report.

    Raises
    ------
    IdentificationError
        A record the fit cannot work with (with the log's plausibility warnings first).
    ValueError
        ``encoder_cpr`` not > 0.

    Examples
    --------
    A record whose excitation rings no clamped mode of the link is refused, saying so:

    >>> import arcosim
    >>> t = np.arange(10001) * 1e-3
    >>> count = 2 * np.pi / 2**17
    >>> theta = np.floor(0.5 * np.sin(3.0 * t) / count) * count
    >>> current = -0.5 * 9.0 * np.sin(3.0 * t) * 2e-4 / 0.0406
    >>> try:
    ...     arcosim.identify_link(t, current, 1.5 * np.cos(3.0 * t), theta,
    ...                   arcosim.Actuator(2.09e-5, 0.0406), encoder_cpr=2**17, L=0.4)
    ... except arcosim.IdentificationError as error:
    ...     print(str(error)[:42])
    the record shows no clamped mode of the li
    """
    if encoder_cpr <= 0:
        raise ValueError(f"encoder_cpr = {encoder_cpr}: the link's fit needs encoder counts (> 0)")
    time, i_a, omega_m, theta_m = (np.asarray(x, float) for x in (time, i_a, omega_m, theta_m))
    geometry = Geometry(L, m_tip, J_tip, r_hub) if L is not None else None
    if fit_friction:  # fitted: τ̂ (the start's modes) is computed without it
        actuator = replace(actuator, D_m=0.0, f_c=0.0)
    k_t, J_m = actuator.k_to + actuator.dkt, actuator.J_mo + actuator.dJm
    plausibility = log_plausibility(time, i_a, omega_m, theta_m, k_t, J_m)
    motor = motor_record(time, i_a, omega_m, theta_m, actuator, g_dist)
    encoder = encoder_record(
        time, i_a, theta_m, actuator, encoder_cpr, not fit_friction, "none", g_dist
    )
    try:
        result = (
            fit_link(encoder, motor, geometry, rhoA=rhoA) if geometry else fit_modes(encoder, motor)
        )
    except IdentificationError as error:
        if not plausibility:
            raise
        raise IdentificationError(f"{'; '.join(plausibility)}; the fit: {error}") from error
    model = modal_of(result, geometry) if geometry else _modes_of(result)
    D_m, f_c = result.extra["D_m"], result.extra["f_c"]
    chain = result.extra["chain"]
    n = int(chain["masses"])
    J, k, B = ([chain[f"{p}[{i}]"] for i in range(1, n + 1)] for p in "JkB")
    if fit_friction:  # τ̂ was computed without it: the fitted friction out
        motor = without_friction(motor, encoder, D_m, f_c)
    residual = predict(motor, J, k, B) - motor.tau_hat
    rms = float(np.sqrt(np.mean(residual**2)))
    floor, sigma_i = noise_floor(time, i_a, (J, k, B), k_t, J_m, encoder_cpr, g_dist)
    warnings = list(plausibility) + list(result.extra.get("warnings", []))
    for text in (
        stiffening_warning(encoder.velocity, float(model.frequency[0])),
        floor_warning(rms, floor, sigma_i),
    ):
        if text:
            warnings.append(text)
    return LinkIdentification(
        fit=result,
        model=model,
        geometry=geometry,
        D_m=D_m,
        f_c=f_c,
        assumptions=link_assumptions(geometry, rhoA),
        warnings=warnings,
        rms_residual=rms,
        duration=motor.duration,
        encoder=encoder,
    )


def _modes_of(result: ParameterFit) -> ModalModel:
    """The modal model of :func:`fit_modes`' result (no tip shape: L unknown)."""
    values = result.as_dict()
    count = sum(name.startswith("omega[") for name in result.names)
    pick = [np.array([values[f"{p}[{i}]"] for i in range(1, count + 1)]) for p in ("omega", "b")]
    zeta = np.array([values[f"zeta[{i}]"] for i in range(1, count + 1)])
    J_link = float(np.sum(pick[1] ** 2)) + values["J_rest"]
    return ModalModel(pick[0], pick[1], np.zeros(count), zeta, J_link, 1.0)
