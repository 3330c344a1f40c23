"""A model against a periodic record's own noise: its misfit at the lines played (offline).

A periodic excitation recorded over M whole periods gives, at each line it plays, M
measurements of the drive's response: their mean is the measured response (the best
linear approximation of the drive at that excitation), their spread over the periods
the noise on it, line by line, whatever its colour (Pintelon & Schoukens, *System
Identification: A Frequency Domain Approach*, 2nd ed., §2.5 and §3.7). A model's
misfit weighted by that noise,

    V = Σ_l |G_model(ω_l) − Ĝ(ω_l)|² / σ̂²(ω_l),

then follows a known law when the model describes the drive: each term is an F(2, ν)
variable (ν = 2(M − 1) degrees of freedom in the estimated variance), whose mean is
ν/(ν − 2) and variance ν³/((ν − 2)²(ν − 4)). A model is **adequate** when V stays within
:data:`SIGMA_RULE` standard deviations of that expectation over the L lines
(:func:`misfit`). Friction and other nonlinear distortion that the excitation drives
period after period stay in the mean (the best linear approximation includes them),
so what the spread measures is the noise alone: a model's misfit above it is model
error or distortion, and a structure is then chosen as the smallest whose misfit is
at the level the best candidate reaches (:func:`smallest_adequate`), the fit untrusted
when that level is above the noise's.

The measured response is the encoder angle's step per sample over the drive torque
(k_t·i_a; rad per N·m), the model's the same quantity from the discrete drive the
prediction-error fit uses (:func:`~arcosim.identification.fit.kalman.discrete_drive`):
the step takes out a constant speed and the angle's offset, which no line carries.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from arcosim.identification.excitation.spectrum import ExcitationSpectrum
from arcosim.identification.fit.kalman import Drive, discrete_drive
from arcosim.identification.records.record import EncoderRecord

#: Least whole periods (a count) a record must hold for its per-line noise: the first is
#: dropped (the transient from rest), and the spread of the mean over the M others needs
#: ν = 2(M − 1) > 4 degrees of freedom for the misfit's law to have a variance (M ≥ 4).
LEAST_PERIODS = 5
#: A model is adequate while its misfit stays within this many standard deviations of
#: its expectation (dimensionless; the three-sigma rule: over hundreds of lines the sum
#: of F(2, ν) terms is near Gaussian, so an adequate model is refused 0.1 % of the time).
SIGMA_RULE = 3.0


@dataclass(frozen=True)
class PeriodicResponse:
    """The drive's response at the lines a periodic excitation plays, and its noise.

    Attributes
    ----------
    w : ndarray
        The lines (rad/s), shape ``(L,)``.
    response : ndarray
        The encoder angle's step per sample over the drive torque, averaged over the
        periods (rad per N·m, complex), shape ``(L,)``.
    variance : ndarray
        The variance of that mean (rad² per (N·m)²), from its spread over the periods,
        shape ``(L,)``.
    periods : int
        Periods averaged (a count; the record's first left out).
    """

    w: np.ndarray
    response: np.ndarray
    variance: np.ndarray
    periods: int

    @property
    def freedom(self) -> int:
        """ν = 2(M − 1), the estimated variance's degrees of freedom (a count)."""
        return 2 * (self.periods - 1)


@dataclass(frozen=True)
class Misfit:
    """A model's misfit at a periodic record's lines (:func:`misfit`).

    Attributes
    ----------
    cost : float
        V, the squared misfit weighted by the per-line noise (dimensionless).
    expected : float
        Its expectation for an adequate model (dimensionless).
    threshold : float
        The largest V an adequate model reaches (:data:`SIGMA_RULE`; dimensionless).
    lines : int
        Lines compared (a count).
    """

    cost: float
    expected: float
    threshold: float
    lines: int

    @property
    def ratio(self) -> float:
        """V over its expectation (dimensionless; about 1 for an adequate model)."""
        return self.cost / self.expected

    @property
    def adequate(self) -> bool:
        """The model explains the response to within its noise."""
        return self.cost <= self.threshold


def periodic_response(
    encoder: EncoderRecord, spectrum: ExcitationSpectrum | None
) -> PeriodicResponse | None:
    """The drive's response at the played lines of a periodic record, averaged over its
    periods, with the noise on it; None unless the excitation is periodic over at least
    :data:`LEAST_PERIODS` whole periods.

    Parameters
    ----------
    encoder : EncoderRecord
        The drive torque (N·m) and encoder angle (rad) of the log, step ``encoder.h``.
    spectrum : ExcitationSpectrum or None
        The log's excitation
        (:func:`~arcosim.identification.excitation.spectrum.excitation_spectrum` of its
        current): its whole periods, its played lines and the record's grid.

    Returns
    -------
    PeriodicResponse or None
        The lines (rad/s), the mean response (rad per N·m) and its variance.

    Examples
    --------
    A rigid drive (J = 1e-3 kg·m²) under a multi-sine of 10 lines, 8 periods of 0.5 s:

    >>> from arcosim.identification.excitation.spectrum import excitation_spectrum
    >>> h, P = 1e-3, 500
    >>> n = np.arange(8 * P)
    >>> torque = sum(np.cos(2 * np.pi * k * n / P + k * k) for k in range(3, 13))
    >>> J = 1e-3
    >>> drive = Drive(np.empty(0), np.empty(0), np.empty(0), 0.0, 0.0, J_rigid=J)
    >>> record = EncoderRecord(h, torque, np.zeros(len(n)), np.zeros(len(n)), 1e-9,
    ...                        0.0, 0.0, 0.0, 1e-9)
    >>> A, Bd = discrete_drive(record, drive)
    >>> x, theta = np.zeros(2), np.zeros(len(n))
    >>> for i in range(1, len(n)):
    ...     x = A @ x + Bd[:, 0] * torque[i]
    ...     theta[i] = x[0]
    >>> record = EncoderRecord(h, torque, np.zeros(len(n)), theta, 1e-9, 0.0, 0.0, 0.0, 1e-9)
    >>> played = torque + 1e-3 * np.random.default_rng(0).standard_normal(len(n))
    >>> response = periodic_response(record, excitation_spectrum(played, h))
    >>> len(response.w), response.periods
    (10, 7)
    >>> model = model_response(record, drive, response.w)
    >>> bool(np.allclose(model, response.response, rtol=1e-6))
    True
    """
    if spectrum is None or spectrum.kind != "periodic" or spectrum.periods < LEAST_PERIODS:
        return None
    h = encoder.h
    samples = round(2.0 * np.pi / (spectrum.resolution * h))
    period = samples // spectrum.periods
    blocks = min(len(encoder.drive), len(encoder.theta_m)) // period
    if blocks < LEAST_PERIODS or period < 4:
        return None
    step = np.diff(encoder.theta_m, prepend=encoder.theta_m[0])
    span = slice(period, blocks * period)  # the first period: the transient from rest
    torque = np.fft.rfft(encoder.drive[span].reshape(blocks - 1, period), axis=1)
    angle = np.fft.rfft(step[span].reshape(blocks - 1, period), axis=1)
    first = 2.0 * np.pi / (period * h)
    bins = np.rint(np.asarray(spectrum.lines, dtype=float) / first).astype(int)
    bins = bins[(bins >= 1) & (bins < torque.shape[1])]
    per_period = angle[:, bins] / torque[:, bins]
    variance = np.var(per_period, axis=0, ddof=1) / (blocks - 1)
    return PeriodicResponse(bins * first, per_period.mean(axis=0), variance, blocks - 1)


def model_response(encoder: EncoderRecord, drive: Drive, w: np.ndarray) -> np.ndarray:
    """The encoder angle's step per sample over the drive torque (rad per N·m, complex)
    of ``drive`` at ``w`` (rad/s, shape ``(L,)``), its step and motor inertia
    ``encoder``'s: ``e₁ᵀ(zI − A)⁻¹ B (z − 1)``, z = e^{jωh}, with the torque of each step
    acting over the step it ends (the fit's timing); shape ``(L,)``."""
    A, Bd = discrete_drive(encoder, drive)
    z = np.exp(1j * np.asarray(w, dtype=float) * encoder.h)
    eye = np.eye(len(A))
    return np.array([np.linalg.solve(zk * eye - A, Bd[:, 0])[0] * (zk - 1.0) for zk in z])


def chain_drive(parameters: dict[str, float], n: int, encoder: EncoderRecord) -> Drive:
    """The drive of a fit's ``parameters`` (by name, each in its unit) of ``n`` masses
    (n = 0: ``J_load`` rigid on the motor): D_m fitted, or the record's when given (0
    when a fit leaves it out); the Coulomb friction left out (not linear: the measured
    response holds its best linear approximation)."""
    J, k, B = (np.array([parameters[f"{x}[{i}]"] for i in range(1, n + 1)]) for x in "JkB")
    D_m = parameters.get("D_m", encoder.D_m if encoder.friction_given else 0.0)
    return Drive(J, k, B, float(D_m), 0.0, J_rigid=parameters.get("J_load", 0.0))


def misfit(response: PeriodicResponse, model: np.ndarray) -> Misfit:
    """A model's misfit (``model``: its response at ``response.w``, rad per N·m, shape
    ``(L,)``) against the response's noise, with its expectation and the largest an
    adequate model reaches (module doc).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> w, truth = np.arange(1.0, 201.0), np.ones(200, dtype=complex)
    >>> noise = (rng.standard_normal(200) + 1j * rng.standard_normal(200)) * 0.01
    >>> response = PeriodicResponse(w, truth + noise, np.full(200, 2e-4), 19)
    >>> misfit(response, truth).adequate, misfit(response, 1.05 * truth).adequate
    (True, False)
    """
    weights = 1.0 / np.maximum(response.variance, 1e-300)
    cost = float(np.sum(np.abs(np.asarray(model) - response.response) ** 2 * weights))
    nu, lines = float(response.freedom), len(response.w)
    mean = nu / (nu - 2.0)
    spread = math.sqrt(lines * nu**3 / ((nu - 2.0) ** 2 * (nu - 4.0)))
    return Misfit(cost, lines * mean, lines * mean + SIGMA_RULE * spread, lines)


def smallest_adequate(misfits: dict[int, Misfit]) -> tuple[int, float]:
    """The smallest structure (its size: a number of masses) whose misfit is adequate,
    each threshold raised by the level the best candidate reaches: the best's misfit
    over its expectation when no candidate is adequate (model error or distortion the
    candidates share), 1 otherwise. Returns the size and that level (dimensionless; 1:
    the structure explains the record within its noise).

    Examples
    --------
    >>> m = lambda cost: Misfit(cost, 240.0, 290.0, 240)
    >>> smallest_adequate({0: m(9000.0), 1: m(250.0), 2: m(245.0)})
    (1, 1.0)
    >>> smallest_adequate({0: m(9e6), 1: m(2.4e6), 2: m(1.5e8)})
    (1, 10000.0)
    """
    adequate = any(m.adequate for m in misfits.values())
    level = 1.0 if adequate else min(m.ratio for m in misfits.values())
    return min(n for n, m in misfits.items() if m.cost <= level * m.threshold), level


def inadequate_reason(n: int, found: Misfit, sizes: Sequence[int]) -> str:
    """The verdict's reason when the chain chosen (``n`` masses, its misfit ``found``)
    does not explain a periodic record to within its noise; ``sizes``: the numbers of
    masses tried."""
    tried = f"n = {min(sizes)} … {max(sizes)}" if len(sizes) > 1 else f"n = {n}"
    return (
        f"no chain ({tried}) explains the response at the {found.lines} lines of the "
        f"periodic excitation to within its noise (their spread over the periods): n = {n} "
        f"misfits {found.ratio:.3g} × what the noise explains. The record holds what "
        "the chain lacks: a delay or the current loop's dynamics, friction, a mode above "
        "the band (--set g_dist=…), or a k_t or J_m off (--set k_to=…, --set J_mo=…)"
    )
