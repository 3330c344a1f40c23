"""The residual's noise floor: what the encoder's counts and the current's noise alone
leave in the whole-chain fit's τ̂ residual (offline).

The fit's residual (``rms_residual``, N·m) is the chain's predicted reaction torque
less the DOB's τ̂_reac on the log. Noise alone leaves some: the encoder's rounding
(uniform, 2π/cpr/√12 rad per sample) through J_m·α̂ and the chain's prediction, and the
current's noise (σ_i, A) through k_t. :func:`noise_floor` runs exactly that pipeline
(:func:`~arcosim.identification.records.motor_record`,
:func:`~arcosim.identification.output_error.predict`) on those noises alone, so the
floor and the residual compare like with like. σ_i is estimated from the record
(:func:`current_noise`: the current's third differences, where a drive's excitation
and control leave little). A residual above :data:`FLOOR_FACTOR` times the floor is
more than noise (:func:`floor_warning` names the likely causes). With a load torque
modelled (``load`` "constant" or "slow") the τ̂ residual holds that torque, which the
chain's prediction leaves out: no comparison then.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.output_error import predict, rigid_predict
from arcosim.identification.records import motor_record

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
    residual = model - record.tau_hat
    return float(np.sqrt(np.mean(residual**2))), sigma_i


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
