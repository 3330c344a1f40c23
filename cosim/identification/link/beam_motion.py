"""A flexible link's motion over a record, and what keeps it in the linear model (offline).

:func:`tip_motion` runs the Kalman smoother (:mod:`arcosim.identification.fit.kalman`) of the
link's modal model (:mod:`arcosim.identification.link.beam_model`, fitted by
:mod:`arcosim.identification.link.beam_fit`) over the record: the modal coordinates
``q_i = b_i (θ_i − θ_m)`` of the star's masses, the tip deflection
``w_tip = Σ φ_i(L) q_i`` plus the quasi-static share of the modes left out (m), its angle
``alpha_tip = w_tip / L`` (rad), and the torque the link exerts on the hub,
``tau_reac = J_rest θ̈ + Σ (k_i (θ_m − θ_i) + B_i (ω_m − ω_i))`` (N·m, eq. 7: in the
rigid limit J_link θ̈). :func:`stiffening_warning` and :func:`link_assumptions` say what
the linear beam model leaves out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from arcosim.identification.fit.kalman import Kalman
from arcosim.identification.link.beam_fit import Geometry, drive_of
from arcosim.identification.link.beam_model import ModalModel
from arcosim.identification.records.record import EncoderRecord
from arcosim.identification.threads import single_threaded

#: The hub's speed over the first clamped mode above which centrifugal stiffening
#: (outside the linear model) is warned of (dimensionless).
STIFFENING_RATIO = 0.3


@dataclass(frozen=True)
class TipMotion:
    """The link's motion over a record, from the Kalman smoother of its modal model.

    Attributes
    ----------
    w_tip : ndarray
        Tip deflection (m), shape ``(N,)``.
    alpha_tip : ndarray
        Tip deflection angle w_tip / L (rad), shape ``(N,)``.
    tau_reac : ndarray
        Torque the link exerts on the hub (N·m, eq. 7), shape ``(N,)``.
    q : ndarray
        Modal coordinates (mass-normalized units), shape ``(N, M)``.
    """

    w_tip: np.ndarray
    alpha_tip: np.ndarray
    tau_reac: np.ndarray
    q: np.ndarray


@single_threaded
def tip_motion(record: EncoderRecord, model: ModalModel, D_m: float, f_c: float) -> TipMotion:
    """The tip's deflection and the reaction torque over ``record`` (offline, smoothed).

    Parameters
    ----------
    record : EncoderRecord
        The current in (N·m), the encoder out (rad).
    model : ModalModel
        The link's modes (:func:`~arcosim.identification.link.beam_model.modal_model` of the
        fitted EI, ρA, with the fitted damping).
    D_m, f_c : float
        The motor's friction (N·m·s/rad, N·m).

    Returns
    -------
    TipMotion
        ``w_tip`` (m), ``alpha_tip`` (rad), ``tau_reac`` (N·m), ``q`` over the record.

    Examples
    --------
    >>> from arcosim import Actuator, encoder_record
    >>> from arcosim.identification import Link, modal_model
    >>> t = np.arange(1000) * 1e-3
    >>> count = 2.0 * np.pi / 2000
    >>> theta = np.floor(np.sin(3.0 * t) / count) * count
    >>> motor = Actuator(J_mo=2.09e-5, k_to=0.0406)
    >>> record = encoder_record(t, 0.1 * np.sin(3.0 * t), theta, motor, 2000)
    >>> model = modal_model(Link(EI=1.0, rhoA=0.1, L=0.4), modes=1)
    >>> motion = tip_motion(record, model, D_m=0.0, f_c=0.0)
    >>> motion.w_tip.shape, motion.q.shape  # N samples, one mode
    ((1000,), (1000, 1))
    """
    drive = drive_of(model, D_m, f_c)
    states = Kalman.of(record, drive).smoothed(record, drive)
    m = len(drive.J) + 1
    angles, rates = states[:, :m], states[:, m : 2 * m]
    q = model.participation * (angles[:, 1:] - angles[:, :1])
    springs = angles @ drive.coupling(drive.k)[0] + rates @ drive.coupling(drive.B)[0]
    friction = drive.D_m * rates[:, 0] + drive.f_c * record.sign
    acceleration = (record.drive - friction - springs) / (record.J_m + drive.J_rigid)
    w_tip = q @ model.tip + model.tip_static * acceleration
    return TipMotion(w_tip, w_tip / model.L, drive.J_rigid * acceleration + springs, q)


def stiffening_warning(omega_m: np.ndarray, first_mode: float) -> str | None:
    """A warning when the hub turns faster than :data:`STIFFENING_RATIO` × the first
    clamped mode (centrifugal stiffening, outside the linear model), else None."""
    peak = float(np.max(np.abs(omega_m))) if len(omega_m) else 0.0
    if peak <= STIFFENING_RATIO * first_mode:
        return None
    return (
        f"the hub turns at up to {peak:.1f} rad/s, more than {STIFFENING_RATIO:g} × the first "
        f"clamped mode ({first_mode:.1f} rad/s): centrifugal stiffening, outside the linear "
        "beam model, raises the modes; the fit's EI absorbs it (record slower motion)"
    )


def link_assumptions(geometry: Geometry | None, rhoA: float | None = None) -> dict[str, str]:
    """What a flexible-link result is conditional on, one line each.

    Parameters
    ----------
    geometry : Geometry or None
        The link's L, m_tip, J_tip, r_hub, or None (a modal model).
    rhoA : float, optional
        The mass per length the user gave (kg/m), held in the fit.

    Returns
    -------
    dict of str to str
        One sentence by topic (``model``, ``actuator``, ``geometry``, ``rhoA``).

    Examples
    --------
    >>> link_assumptions(Geometry(0.3), rhoA=0.02)["rhoA"][:33]
    'given: ρA = 0.02 kg/m, not fitted'
    """
    out = {
        "model": "Euler–Bernoulli beam clamped to the hub, small deflection in the rotating "
        "frame, no centrifugal stiffening, no gravity, no torsion; modes above the record's "
        "band rigid on the hub",
        "actuator": "k_t and J_m are given, not fitted: an error ε in both scales EI, ρA and the "
        "friction by 1 + ε",
    }
    if geometry is not None:
        out["geometry"] = (
            f"given: L = {geometry.L:g} m, m_tip = {geometry.m_tip:g} kg, "
            f"J_tip = {geometry.J_tip:g} kg.m², r_hub = {geometry.r_hub:g} m"
        )
    else:
        out["geometry"] = "not given: a modal model (frequencies, damping, hub participation)"
    if rhoA is not None:
        out["rhoA"] = (
            f"given: ρA = {rhoA:g} kg/m, not fitted (no standard error); EI follows from "
            "the first clamped mode at this ρA, so an error ε in ρA gives EI an error of ε "
            "without a tip mass, less with one (+10 % in ρA: +1.2 % in EI with a tip "
            "of 1.7 times the link's mass); "
            "the first mode above the band is kept flexible"
        )
    return out
