"""The residual's noise floor: what the encoder's counts and the current's noise alone
leave in the whole-chain fit's τ̂ residual (offline).

The fit's residual (``rms_residual``, N·m) is the chain's predicted reaction torque
less the DOB's τ̂_reac on the log. Noise alone leaves some: the encoder's rounding
(uniform, 2π/cpr/√12 rad per sample) through J_m·α̂ and the chain's prediction, and the
current's noise (σ_i, A) through k_t. :func:`noise_floor` runs exactly that pipeline
(:func:`~arcosim.identification.records.record.motor_record`,
:func:`~arcosim.identification.fit.output_error.predict`) on those noises alone, so the
floor and the residual compare like with like. σ_i is estimated from the record
(:func:`current_noise`: the current's third differences, where a drive's excitation
and control leave little). A residual above :data:`FLOOR_FACTOR` times the floor is
more than noise (:func:`floor_warning` names the likely causes). With a load torque
modelled (``load`` "constant" or "slow") the τ̂ residual holds that torque, which the
chain's prediction leaves out: it lies below the excitation, and the residual and the
floor are compared without their content there (:func:`load_removed`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from arcosim.fmu.flexchain.defaults import VELOCITY_SMOOTHING
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.fit.output_error import predict, rigid_predict, through_g
from arcosim.identification.records.low_pass import low_passed
from arcosim.identification.records.record import MotorRecord, motor_record

#: A residual this many times the noise floor (dimensionless) warns. Noise alone gives
#: about 1×; on good logs of the independent simulator (seed 0) the friction model's
#: small errors add up to 3.55× at 10 kHz (the floor falls as √h, they do not; 0.8–1.6×
#: at 1–4 kHz, 3.1× on the three-mass chain at 4 kHz; the sample log 1.4×), while k_t
#: 10 % off gives 3.2–16× (the sample log 4.3×, its J_m 10 % high 3.1×: missed). 4
#: keeps every good log measured quiet and catches k_t 10 % off on 5 of 8 logs.
FLOOR_FACTOR = 4.0
#: The likely causes of a residual above the floor, and what to try (one clause).
CAUSES = (
    "check k_t and J_m (--set k_to=…, --set J_mo=…; 10 % off gives 3–16 ×), "
    "the columns' units (--scale), an unmodelled load torque (--load slow), the "
    "friction (--set D_m=… f_c=…) or a mode outside the band"
)
#: Seed of the simulated noise (the floor is a property of the log, not a draw).
FLOOR_SEED = 0


def current_noise(i_a: np.ndarray) -> float:
    """The current's white noise (A, standard deviation per sample), estimated from the
    record: the third differences' robust spread (1.4826·MAD) over √20 (a white
    noise's third difference has 20 times its variance; a line at ω moves it by
    (ω·h)³ of its amplitude only, 0.3 % at 150 rad/s and 1 kHz).

    Parameters
    ----------
    i_a : ndarray
        The logged current (A), shape ``(N,)``.

    Returns
    -------
    float
        The noise's standard deviation (A); an overestimate when the current holds
        fast content of its own (a control loop's ripple): the floor errs high, never
        into a false warning.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(20000) * 1e-3
    >>> round(current_noise(np.sin(3 * t) + 0.01 * rng.standard_normal(len(t))), 3)
    0.01
    """
    d3 = np.diff(np.asarray(i_a, dtype=float), 3)
    return float(1.4826 * np.median(np.abs(d3 - np.median(d3))) / np.sqrt(20.0))


def noise_floor(
    time: np.ndarray,
    i_a: np.ndarray,
    chain: tuple[Sequence[float], Sequence[float], Sequence[float]],
    k_t: float,
    J_m: float,
    encoder_cpr: int,
    g_dist: float,
    J_load: float = 0.0,
    below: float | None = None,
) -> tuple[float, float]:
    """The RMS τ̂ residual (N·m) the encoder's counts and the current's noise alone leave.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    i_a : ndarray
        The logged current (A), shape ``(N,)``: its noise is estimated from it.
    chain : tuple of three sequences of float
        The fitted J_i (kg·m²), k_i (N·m/rad), B_i (N·m·s/rad); empty for a rigid
        drive (n = 0).
    k_t : float
        Torque constant (N·m/A).
    J_m : float
        Motor inertia (kg·m²).
    encoder_cpr : int
        Encoder counts per revolution (a count); 0: no rounding.
    g_dist : float
        Bandwidth of the disturbance observer (rad/s).
    J_load : float
        A rigid drive's load inertia J_total − J_m (kg·m²), used when ``chain`` is empty.
    below : float or None
        With a load torque modelled: the residual's mean and its content below this
        frequency (rad/s; 0: the mean only) are the load's and are left out
        (:func:`load_removed`); None: no load modelled.

    Returns
    -------
    tuple of float
        The floor (N·m, RMS) and the current noise it assumed (A, estimated from the
        record).
    """
    rng = np.random.default_rng(FLOOR_SEED)
    count = 2.0 * np.pi / encoder_cpr if encoder_cpr > 0 else 0.0
    sigma_i = current_noise(i_a)
    theta = count * rng.uniform(-0.5, 0.5, len(time))
    current = sigma_i * rng.standard_normal(len(time))
    omega = np.concatenate([[0.0], np.diff(theta)]) / float(np.mean(np.diff(time)))
    record = motor_record(time, current, omega, theta, Actuator(J_m, k_t), g_dist)
    model = predict(record, *chain) if len(chain[0]) else rigid_predict(record, J_load)
    residual = model - record.tau_hat + smoothing_error(record, current, k_t, model)
    return _rms(load_removed(residual, record.h, below)), sigma_i


def smoothing_error(
    record: MotorRecord, i_a: np.ndarray, k_t: float, model: np.ndarray
) -> np.ndarray:
    """The τ̂ error the observer's velocity smoothing leaves, to be added to the residual
    ``model − record.tau_hat``: (1 − F)[G[k_t·i_a] − model].

    Offline the motor's velocity is the angle's derivative smoothed at
    ``VELOCITY_SMOOTHING``·g_dist (F, zero phase;
    :func:`~arcosim.identification.records.record.motor_record`), so τ̂ = G[k_t·i − J_m·F[α] −
    friction] carries G[(1 − F)·J_m·α] besides the reaction torque: nothing of the
    chain, and no noise, but the motor's own acceleration where F cuts it. A
    multi-sine below the band barely reaches F's cut (1 − F is 2 % at 150 rad/s with
    g_dist = 100 rad/s); a PRBS or noise to 1100 rad/s does, and it was 80 % of the
    residual's power on a PRBS log, 24 × the floor although the fit was right. Since
    J_m·α = k_t·i − τ_reac − friction, G[J_m·α] is G[k_t·i] less the model's τ̂
    (the friction's part, F's cut above the band, left out).

    Parameters
    ----------
    record : MotorRecord
        The record the residual is taken on (its step, g_dist and velocity source).
    i_a : ndarray
        The current that built it (A), shape ``(N,)``.
    k_t : float
        Torque constant (N·m/A).
    model : ndarray
        The model's τ̂ on the record (N·m), shape ``(N,)``.

    Returns
    -------
    ndarray
        The term (N·m), shape ``(N,)``; zeros when the record's velocity was logged,
        not smoothed.

    Examples
    --------
    A drive torque far above F's cut (2000 rad/s at 400) passes into τ̂ through G
    only: the term is that, 100/2000 of it.

    >>> from arcosim.identification.records.record import MotorRecord
    >>> t = np.arange(20000) * 1e-4
    >>> record = MotorRecord(1e-4, np.zeros(20000), np.zeros(20000), 100.0, "smoothed")
    >>> term = smoothing_error(record, np.sin(2000 * t), 1.0, np.zeros(20000))
    >>> round(float(np.abs(term[5000:15000]).max()), 3)
    0.05
    """
    if record.velocity_source == "measured":
        return np.zeros(len(model))
    h, g = record.h, record.g_dist
    x = through_g(k_t * np.asarray(i_a, dtype=float), g, h) - model
    return x - low_passed(x, h, VELOCITY_SMOOTHING * g)


def tau_residual(
    record: MotorRecord,
    i_a: np.ndarray,
    k_t: float,
    chain: tuple[Sequence[float], Sequence[float], Sequence[float]],
    J_load: float = 0.0,
    below: float | None = None,
) -> float:
    """The fit's RMS τ̂ residual (N·m) as the floor is taken: the model's τ̂ less the
    record's, the velocity smoothing's error (:func:`smoothing_error`) taken out.

    Parameters
    ----------
    record : MotorRecord
        The log's record, its friction (given or fitted) taken out of τ̂.
    i_a : ndarray
        The logged current (A), shape ``(N,)``.
    k_t : float
        Torque constant (N·m/A).
    chain : tuple of three sequences of float
        The fitted J_i (kg·m²), k_i (N·m/rad), B_i (N·m·s/rad); empty for n = 0.
    J_load : float
        A rigid drive's load inertia (kg·m²), used when ``chain`` is empty.
    below : float or None
        With a load torque modelled: leave out the residual's mean and its content below
        this frequency (rad/s; 0: the mean only; :func:`load_removed`); None: no load
        modelled.

    Returns
    -------
    float
        The RMS residual (N·m).
    """
    model = predict(record, *chain) if len(chain[0]) else rigid_predict(record, J_load)
    residual = model - record.tau_hat + smoothing_error(record, i_a, k_t, model)
    return _rms(load_removed(residual, record.h, below))


def load_removed(residual: np.ndarray, h: float, below: float | None) -> np.ndarray:
    """``residual`` (N·m, shape ``(N,)``, step ``h`` in s) without what a modelled load
    torque puts in it: its mean and its content below ``below`` (rad/s; 0: the mean
    only); ``residual`` itself when ``below`` is None (no load modelled).

    A load on the last mass slower than the chain's first mode reaches the motor whole,
    so it sits in the τ̂ residual below the excitation, where the chain's prediction has
    nothing; the floor is taken through the same filter, so the two still compare.

    Examples
    --------
    >>> t = np.arange(40000) * 1e-3
    >>> slow_and_fast = 0.5 + np.sin(0.2 * t) + 0.01 * np.sin(50 * t)
    >>> left = load_removed(slow_and_fast, 1e-3, 1.5) - 0.01 * np.sin(50 * t)
    >>> bool(np.abs(left[5000:-5000]).max() < 1e-3)  # the slow part gone, the fast kept
    True
    """
    if below is None:
        return residual
    residual = residual - np.mean(residual)
    return residual - low_passed(residual, h, below) if below > 0 else residual


def _rms(x: np.ndarray) -> float:
    """Root mean square of ``x`` (its unit)."""
    return float(np.sqrt(np.mean(np.asarray(x) ** 2)))


def floor_warning(rms_residual: float, floor: float, sigma_i: float) -> str | None:
    """A warning when the fit's residual is above :data:`FLOOR_FACTOR` × the noise floor.

    Parameters
    ----------
    rms_residual : float
        The fit's RMS τ̂ residual (N·m).
    floor : float
        The noise floor (N·m, :func:`noise_floor`).
    sigma_i : float
        The current noise the floor assumed (A).

    Returns
    -------
    str or None
        The warning, naming the likely causes; None at or near the floor.

    Examples
    --------
    >>> floor_warning(1e-3, 5e-4, 0.01) is None
    True
    >>> floor_warning(2.5e-3, 5e-4, 0.01)[:40]
    'the residual (0.0025 N·m) is 5 × the noi'
    """
    if not (floor > 0 and rms_residual > FLOOR_FACTOR * floor):
        return None
    return (
        f"the residual ({rms_residual:.3g} N·m) is {rms_residual / floor:.2g} × the noise "
        f"floor the encoder and the current noise explain ({floor:.3g} N·m; current noise "
        f"{sigma_i:.3g} A estimated from the record; warns above {FLOOR_FACTOR:g} ×): "
        f"{CAUSES}"
    )


def weak_mode_floor_warning(
    dropped: Sequence[float], rms_without: float, floor: float, sigma_i: float
) -> str | None:
    """A warning when the fit without its weakly determined modes is above
    :data:`FLOOR_FACTOR` × the noise floor: those modes may be real, or take up what a
    wrong k_t or J_m leaves (k_t high puts 0.1·J_m·α into τ̂, an inertia on the motor
    that a weak mode above the others fits).

    Parameters
    ----------
    dropped : sequence of float
        The weakly determined modes the fit keeps (rad/s).
    rms_without : float
        The RMS τ̂ residual of the fit without them (N·m).
    floor : float
        The noise floor (N·m, :func:`noise_floor`).
    sigma_i : float
        The current noise the floor assumed (A).

    Returns
    -------
    str or None
        The warning, naming the modes and the likely causes; None at or near the floor.

    Examples
    --------
    >>> weak_mode_floor_warning([137.0], 1e-3, 5e-4, 0.01) is None
    True
    >>> weak_mode_floor_warning([137.0], 3.5e-3, 5e-4, 0.01)[:45]
    'the weakly determined mode at 137 rad/s takes'
    """
    if not (floor > 0 and rms_without > FLOOR_FACTOR * floor):
        return None
    modes = ", ".join(f"{w:.4g}" for w in dropped)
    return (
        f"the weakly determined mode at {modes} rad/s takes up the misfit: without it the "
        f"residual ({rms_without:.3g} N·m) is {rms_without / floor:.2g} × the noise floor "
        f"the encoder and the current noise explain ({floor:.3g} N·m; current noise "
        f"{sigma_i:.3g} A estimated from the record; warns above {FLOOR_FACTOR:g} ×): "
        f"it may be a mode, or stand in for an error: {CAUSES}"
    )
