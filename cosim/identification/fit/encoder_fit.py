"""Prediction-error identification of the whole drive: from the motor current to the encoder.

Motor and chain are one linear model driven by the motor torque
``k_t i_a − f_c s_k`` (s_k the friction's sign over the step: first from the angle's
derivative smoothed without lag, then from the Kalman smoother's states, stuck-aware:
while the smoothed motor velocity stays below :data:`STUCK_VELOCITY_COUNTS` counts per
second, the friction is the torque that holds the motor, within ±f_c). The encoder
measures the motor angle with a uniform error of one count (variance q²/12), and an
unmodelled torque on the motor (the friction's error, current noise; standard
deviation :func:`~arcosim.identification.records.record.torque_std`) is the process noise.
The steady-state Kalman predictor (:mod:`arcosim.identification.fit.kalman`) gives the
innovations, and least squares on them (:func:`refine`) is the prediction-error estimate
(Ljung, *System Identification*, ch. 7). Being a predictor of the encoder from the
current, it is consistent with the drive's own speed or position loop closed around
it (closed-loop data: the current then depends on the noise; the direct method).

Besides every J_i, k_i, B_i it can fit

* the motor's friction D_m, f_c (when the user gives only k_t and J_m:
  ``friction_given=False``); the values in the record are then the start;
* a load torque on the last mass: a constant τ_L (``load="constant"``), or a constant
  plus a random walk (the record's ``load_std`` per step,
  :data:`~arcosim.identification.records.record.LOAD_DRIFT` of the rms drive torque per √s)
  that the Kalman filter tracks (``load="slow"``), for a load that drifts slower than
  the first mode.

k_t and J_m are given, not fitted: a relative error ε in both scales every J_i, k_i,
B_i, D_m, f_c and τ_L by (1 + ε) (the model is homogeneous in torque); an error in
J_m alone shows as an error of the first inertia mostly.

The record it reads is :class:`arcosim.identification.records.record.EncoderRecord`
(:func:`~arcosim.identification.records.record.encoder_record`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import optimize

from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.kalman import Drive, Kalman, discrete_drive, innovations
from arcosim.identification.fit.newey_west import (
    decorrelation_lag,
    newey_west_covariance,
    significance_lag,
)
from arcosim.identification.fit.output_error import ParameterFit, predict
from arcosim.identification.records.record import EncoderRecord, MotorRecord, mean_sign

#: Below this smoothed motor speed (encoder counts per second) the motor is taken as
#: stuck in the second pass: its friction is the torque that holds it (within ±f_c).
STUCK_VELOCITY_COUNTS = 20.0

#: Smoothings that set a rigid drive's friction sign in the second pass, each with the
#: sign the one before found (:func:`smoothed_sign`; one leaves a lag of ~1.5 ms at
#: reversals). A chain keeps one: more tipped a three-mass chain's friction form to
#: Coulomb only (B_1 +120 %, ``tests/test_field_identification.py``); open.
SIGN_ITERATIONS = 4

#: Passes of a rigid drive's fit (n = 0, cheap) after the first, each with the sign
#: smoothed with the pass before's drive: the sign of a slow slide or a stop settles
#: over passes (on a 10 s ball-screw record, truth 2e-5: D_m 0 without them, 1.0e-5
#: with 3 passes, 1.3e-5 with 6 passes of 8 smoothings: it settles slowly).
RIGID_PASSES = 3

#: Iterations of each least-squares pass (a start from the record's modes converges
#: in 5–15; a chain with a mode the record does not have wanders).
MAX_ITERATIONS = 40


#: The rigid drive's (n = 0) one chain parameter: the load inertia J_total − J_m (kg·m²).
RIGID_LOAD = "J_load"
#: The SI units of the fit's parameters that are not the chain's
#: (:data:`arcosim.fmu.flexchain.chain.UNITS` holds those): the rigid drive's load
#: inertia and a modelled load torque.
FIT_UNITS = {RIGID_LOAD: "kg·m²", "tau_load": "N·m"}


def chain_size(n: int) -> int:
    """Chain parameters of an n-mass fit (a count): 3n, or 1 for the rigid drive (n = 0:
    the load inertia :data:`RIGID_LOAD`)."""
    return 3 * n if n else 1


def fitted_friction(record: EncoderRecord) -> tuple[str, ...]:
    """The friction terms the fit carries: none when given, else those of the record's
    ``friction_form`` (``D_m`` for viscous, ``f_c`` for Coulomb, both)."""
    if record.friction_given:
        return ()
    return {"none": (), "viscous": ("D_m",), "coulomb": ("f_c",), "both": ("D_m", "f_c")}[
        record.friction_form
    ]


def parameter_names(n: int, record: EncoderRecord) -> list[str]:
    """Fit order: ``J[i]``, ``k[i]``, ``B[i]`` (n = 0: ``J_load``, the rigid drive's load
    inertia J_total − J_m), then ``D_m``, ``f_c`` (friction not given), then
    ``tau_load`` (a load torque modelled)."""
    names = [f"{p}[{i}]" for p in ("J", "k", "B") for i in range(1, n + 1)] or [RIGID_LOAD]
    names += list(fitted_friction(record))
    if record.load != "none":
        names.append("tau_load")
    return names


def unpack(p: np.ndarray, n: int, record: EncoderRecord) -> Drive:
    """The drive of parameter vector ``p`` (:func:`parameter_names` order)."""
    J, k, B = p[:n], p[n : 2 * n], p[2 * n : 3 * n]
    rigid = 0.0 if n else float(p[0])
    j = chain_size(n)
    friction = {"D_m": record.D_m, "f_c": record.f_c}
    for name in fitted_friction(record):
        friction[name] = p[j]
        j += 1
    D_m, f_c = friction["D_m"], friction["f_c"]
    tau = p[j] if record.load != "none" else 0.0
    return Drive(J, k, B, float(D_m), float(f_c), float(tau), J_rigid=rigid)


def pack(drive: Drive, record: EncoderRecord) -> np.ndarray:
    """Inverse of :func:`unpack`."""
    p = [*drive.J, *drive.k, *drive.B] if len(drive.J) else [drive.J_rigid]
    p += [{"D_m": drive.D_m, "f_c": drive.f_c}[name] for name in fitted_friction(record)]
    if record.load != "none":
        p.append(drive.tau_load)
    return np.array(p, dtype=float)


def stuck_aware_sign(record: EncoderRecord, drive: Drive, states: np.ndarray) -> np.ndarray:
    """The friction's s_k from smoothed states (N, S): sgn ω where the motor moves;
    where it is stuck (|ω| below :data:`STUCK_VELOCITY_COUNTS` counts/s and the torque
    on it other than friction, ``k_t i − D_m ω −`` spring and damper torques, within
    ±f_c) the share of f_c that holds it, that torque / f_c. A motor slow but driven
    harder than f_c is passing through 0, not stuck: taking the drive's sign there
    turned the friction before the motor did (J_load −0.2 % on a ball-screw axis).
    That torque test is made for the rigid drive (n = 0) only: on a three-mass chain
    (``tests/test_field_identification.py``) it tipped the friction form to Coulomb
    only (B_1 +120 %), the torque then leaving out the chain's own inertia; open."""
    n = len(drive.J)
    m = n + 1
    omega = states[:, m]
    K, C = drive.coupling(drive.k)[0], drive.coupling(drive.B)[0]
    spring = states[:, :m] @ K + states[:, m : 2 * m] @ C  # the springs' torque on the motor
    other = record.drive - drive.D_m * omega - spring
    sign = mean_sign(omega)
    slow = np.abs(omega) < STUCK_VELOCITY_COUNTS * record.count
    if n == 0:  # a torque above f_c moves it through 0 (see the docstring)
        slow &= np.abs(other) <= drive.f_c
    stuck = slow
    if drive.f_c > 0:
        sign[stuck] = np.clip(other[stuck] / drive.f_c, -1.0, 1.0)
    return sign


def settled_sign(record: EncoderRecord, drive: Drive, states: np.ndarray) -> np.ndarray:
    """The friction's s_k from smoothed states (N, S) and the sign they were smoothed
    with (``record.sign``): sgn ω where the motor moves; where it is slow (|ω| below
    :data:`STUCK_VELOCITY_COUNTS` counts/s) that sign less the torque the smoother
    finds unmodelled over the step (the process noise ŵ_k, N·m, the states' step
    residual projected on the torque's input column) over f_c, within ±1: the friction
    that the encoder's counts ask for, whether the motor sticks, slides to a stop or
    breaks away (the stuck rule of :func:`stuck_aware_sign` takes a slow slide for a
    stop)."""
    A, Bd = discrete_drive(record, drive)
    b = Bd[:, 0]
    before = record.sign
    torque = record.drive - drive.f_c * before
    step = states[1:].T - A @ states[:-1].T - np.outer(b, torque[1:])
    unmodelled = np.concatenate([[0.0], (b @ step) / (b @ b)])
    omega = states[:, len(drive.J) + 1]
    sign = mean_sign(omega)
    slow = np.abs(omega) < STUCK_VELOCITY_COUNTS * record.count
    if drive.f_c > 0:
        sign[slow] = np.clip(before[slow] - unmodelled[slow] / drive.f_c, -1.0, 1.0)
    return sign


def smoothed_sign(record: EncoderRecord, drive: Drive, rounds: int) -> EncoderRecord | None:
    """``record`` with the friction's sign (:func:`stuck_aware_sign`) and velocity of
    the Kalman smoother's states for ``drive``, smoothed ``rounds`` times (a count),
    each with the sign the one before found; None when the smoother diverges.

    The smoother pins the angle to the encoder, so a friction sign that turns late
    drives its velocity through 0 late too (the torque ±f_c it holds too long bends
    the velocity that the counts fix): the sign of one smoothing keeps its own lag
    (1.5 ms on a ball-screw record, enough to take 10 % of D_m for Coulomb friction).
    Smoothing again with the sign it gave takes the lag out in 2–3 rounds (to < 0.1 ms
    with the true drive). The first round's sign is :func:`stuck_aware_sign`, the
    others :func:`settled_sign`.
    """
    for round in range(rounds):
        with np.errstate(all="ignore"):
            states = Kalman.of(record, drive).smoothed(record, drive)
        if not np.all(np.isfinite(states)):
            return None
        rule = settled_sign if round else stuck_aware_sign
        record = replace(
            record,
            friction_sign=rule(record, drive, states),
            velocity=states[:, len(drive.J) + 1],
        )
    return record


def refine(
    record: EncoderRecord,
    motor: MotorRecord | None,
    start: ParameterFit,
    n: int,
    more_rounds: int = 0,
) -> ParameterFit:
    """Prediction-error fit of the drive from ``start``, in two passes: the friction's
    sign first from the record's velocity, then stuck-aware from the Kalman smoother's
    states with the first pass's drive (:func:`stuck_aware_sign`).

    Standard errors: Newey–West on the innovations' score, its bandwidth
    :func:`~arcosim.identification.fit.newey_west.significance_lag` (the innovations are
    nearly white, not white: a small correlation persists over dozens of lags).

    Parameters
    ----------
    record : EncoderRecord
        The drive torque in (N·m) and the encoder's angle out (rad).
    motor : MotorRecord or None
        The same log's τ̂_reac record, only for the reported τ̂ residual (N·m).
    start : ParameterFit
        An n-mass fit whose first 3n values are J_i (kg·m²), k_i (N·m/rad), B_i
        (N·m·s/rad).
    n : int
        Number of load masses (a count).
    more_rounds : int
        Smoothings of the friction's sign beyond the usual (a count; see
        :func:`smoothed_sign`), to measure how far the sign moves the friction.

    Returns
    -------
    ParameterFit
        J_i, k_i, B_i (then D_m, f_c when fitted, then the load torque; names by
        :func:`parameter_names`) with standard errors; ``extra`` holds the criterion,
        the innovations' variance, the friction and the load.
    """
    chain = np.asarray(start.values[: chain_size(n)], dtype=float).copy()
    if n:
        floor = 1e-3 * np.mean(chain[2 * n :]) if np.any(chain[2 * n :] > 0) else 1e-9
        chain[2 * n :] = np.maximum(chain[2 * n :], floor)
    rigid = 0.0 if n else float(chain[0])
    first = pack(
        Drive(
            chain[:n], chain[n : 2 * n], chain[2 * n :], record.D_m, record.f_c, 0.0, J_rigid=rigid
        ),
        record,
    )
    values, residual, jac, evaluations = _least_squares(record, first, n)
    drive = unpack(values, n, record)
    more = 0
    for _ in range(RIGID_PASSES if n == 0 else 1):
        signed = smoothed_sign(record, drive, (SIGN_ITERATIONS if n == 0 else 1) + more_rounds)
        if signed is None:  # the last pass's drive is no chain to smooth with
            break
        record = signed
        values, residual, jac, runs = _least_squares(record, values, n)
        drive, more = unpack(values, n, record), more + runs
    drive = unpack(values, n, record)
    lag = decorrelation_lag(residual, 1)  # the BIC's effective sample count
    std_lag = significance_lag(residual, lag)  # σ: until the correlation is noise
    std = np.sqrt(np.clip(np.diag(newey_west_covariance(jac, residual, std_lag)), 0.0, None))
    extra = {
        **start.extra,
        "bounds": at_bound(parameter_names(n, record), values, std, first),
        "information_criterion": innovation_criterion(residual, len(values)),
        "start_fit": start.as_dict(),
        "innovation_variance": float(np.mean(residual**2)),
        "innovation_count": len(residual),
        "std_lag": std_lag,
        "torque_std": record.torque_std,
        "friction": "given" if record.friction_given else "fitted",
        "friction_form": "given" if record.friction_given else record.friction_form,
        "load": record.load,
        "D_m": drive.D_m,
        "f_c": drive.f_c,
    }
    if record.load == "slow":
        states = Kalman.of(record, drive).smoothed(record, drive)
        load = drive.tau_load + states[:, -1]
        extra["load_torque_range"] = [float(load.min()), float(load.max())]
    rms = start.rms_residual
    if motor is not None and n:
        tau_residual = predict(motor, drive.J, drive.k, drive.B) - motor.tau_hat
        rms = float(np.sqrt(np.mean(tau_residual**2)))
    return ParameterFit(
        names=parameter_names(n, record),
        values=values,
        std=std,
        start=first,
        start_note=start.start_note
        + "; then the prediction-error fit from the current to the encoder",
        rms_residual=rms,
        rms_data=start.rms_data,
        lag=lag,
        evaluations=start.evaluations + evaluations + more,
        extra=extra,
    )


def at_bound(
    names: list[str], values: np.ndarray, std: np.ndarray, first: np.ndarray
) -> dict[str, float]:
    """The parameters at their lower bound 0 (a damping, D_m, f_c), each with the
    upper bound the record allows: its value + 2σ, or its start when σ is degenerate
    (0: the record does not resolve it). Units: each parameter's own.

    Examples
    --------
    >>> at_bound(["B[1]", "D_m"], np.array([1e-5, 1e-15]), np.array([1e-6, 0.0]),
    ...          np.array([1e-5, 3e-6]))
    {'D_m': 3e-06}
    """
    out = {}
    for name, value, sigma, start in zip(names, values, std, first):
        if name[0] in "BDf" and value <= 1e-6 * max(abs(start), 1e-12):
            resolved = sigma > 1e-6 * abs(start)
            out[name] = float(value + 2.0 * sigma) if resolved else float(abs(start))
    return out


def innovation_criterion(innovations: np.ndarray, parameters: int) -> float:
    """Bayesian information criterion of a prediction-error fit: ``N log(mean e²) +
    P log N`` on the normalized innovations (nearly white, so N counts samples)."""
    count = len(innovations)
    return float(count * np.log(np.mean(innovations**2)) + parameters * np.log(count))


def _least_squares(
    record: EncoderRecord, first: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Least squares on the innovations from ``first``: the values, the innovations,
    their Jacobian by parameter (N − 1, P) and the model runs used. Each parameter is
    scaled by its start (the load torque by the rms drive torque / 100: it may be 0)."""
    names = parameter_names(n, record)
    scale = np.abs(first).astype(float)
    lower = np.zeros(len(first))
    lower[: 2 * n] = 1e-3  # inertias and stiffnesses above a thousandth of their start
    if record.load != "none":
        torque = float(np.sqrt(np.mean(record.drive**2)))
        scale[-1] = max(abs(first[-1]), 1e-2 * torque)
        lower[-1] = -np.inf
    for j, name in enumerate(names):
        if name in ("D_m", "f_c"):
            scale[j] = max(scale[j], 1e-9)
    x0 = first / scale

    def residual(x: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            e = innovations(record, unpack(x * scale, n, record))
        if not np.all(np.isfinite(e)):
            raise IdentificationError(
                f"the prediction-error fit of {n} mass(es) diverged (the record does not "
                "determine that chain): excite the modes better or fit fewer masses"
            )
        return e

    result = optimize.least_squares(
        residual,
        x0,
        bounds=(lower, np.inf),
        x_scale="jac",
        diff_step=1e-6,
        max_nfev=MAX_ITERATIONS,
    )
    runs = int(result.nfev * (len(first) + 1))
    return result.x * scale, result.fun, result.jac / scale, runs
