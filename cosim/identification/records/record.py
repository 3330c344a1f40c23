"""The two records every fit reads from a drive log (offline).

* :class:`MotorRecord` (:func:`motor_record`): the motor angle and the reaction torque
  observer's estimate τ̂_reac computed from the same log
  (:class:`arcosim.fmu.flexchain.dob.ReactionObserver`, the code the observer FMU runs),
  what the modal start and the output-error fits read;
* :class:`EncoderRecord` (:func:`encoder_record`): the drive torque ``k_t i_a`` in, the
  encoder's counts out, with the motor's friction model, what the prediction-error fit
  from the current to the encoder reads (:mod:`arcosim.identification.fit.encoder_fit`).

Both need a constant sample step (:func:`constant_step`) and take the motor velocity as
the derivative of the angle smoothed without lag (:func:`smooth_velocity`): the motor
record when the log's own velocity is the encoder's backward difference, the encoder
record always (for the friction's sign). :func:`motor_opening` and
:func:`encoder_opening` cut a record's first seconds (the fits' short openings).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import signal

from arcosim.fmu.flexchain.defaults import G_DIST, VELOCITY_SMOOTHING
from arcosim.fmu.flexchain.dob import Actuator, ReactionObserver
from arcosim.identification.errors import IdentificationError
from arcosim.identification.records.low_pass import low_passed


@dataclass(frozen=True)
class MotorRecord:
    """A motor-side record ready for fitting: the motor angle and τ̂_reac.

    Attributes
    ----------
    h : float
        The (constant) step (s).
    theta_m : ndarray
        Measured motor angle at each sample (rad), shape ``(N,)``.
    tau_hat : ndarray
        τ̂_reac after each sample (N·m), shape ``(N,)``; sample 0 is the start.
    g_dist : float
        The DOB bandwidth used for ``tau_hat`` (rad/s).
    velocity_source : str
        Which motor velocity the DOB was given (a sentence for the report).
    velocity : ndarray or None
        That velocity (rad/s), shape ``(N,)``: the rigid drive's prediction of τ̂ reads
        its differences as the DOB does; None when not kept.

    Examples
    --------
    >>> t = np.arange(1000) * 1e-3
    >>> motor = Actuator(J_mo=2.09e-5, k_to=0.0406)
    >>> record = motor_record(t, 0.1 * np.sin(3.0 * t), 3.0 * np.cos(3.0 * t),
    ...                       np.sin(3.0 * t), motor, 100.0)
    >>> isinstance(record, MotorRecord), record.h, record.g_dist  # s, rad/s
    (True, 0.001, 100.0)
    """

    h: float
    theta_m: np.ndarray
    tau_hat: np.ndarray
    g_dist: float
    velocity_source: str = "measured"
    velocity: np.ndarray | None = None

    @property
    def duration(self) -> float:
        """Record length (s)."""
        return self.h * (len(self.theta_m) - 1)


#: Largest reaction torque (N·m) a record may carry: far beyond any drive, and small
#: enough that the fits' sums of squares over 10⁷ samples stay finite.
MAX_TORQUE = 1e100


def constant_step(time: np.ndarray, what: str = "the log") -> float:
    """The step of a uniformly sampled time column (s).

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    what : str
        What the column belongs to, for messages.

    Returns
    -------
    float
        The mean step (s).

    Raises
    ------
    IdentificationError
        For fewer than 3 samples, or a step that varies by more than 1e-6 of its mean.
    """
    steps = np.diff(np.asarray(time, dtype=float))
    if len(steps) < 2:
        raise IdentificationError(f"{what} has fewer than 3 samples; output-error needs a record")
    h = float(np.mean(steps))
    if np.max(np.abs(steps - h)) > 1e-6 * h:
        raise IdentificationError(
            f"{what}: output-error identification needs a constant sample step "
            f"(steps range {steps.min():.6g} … {steps.max():.6g} s); resample the log"
        )
    return h


def motor_record(
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta_m: np.ndarray,
    actuator: Actuator,
    g_dist: float,
) -> MotorRecord:
    """Run the reaction torque observer over a log: the record the chain fits use.

    When the log's velocity is the encoder's backward difference (a realistic drive,
    and the plant FMU with an encoder), two things go wrong offline that need not:
    the DOB's pairing of the velocity change with the step's current is off by half a
    step (J_m·α lags by h/2, an error in quadrature that the fit takes for damping),
    and a velocity that jumps by whole counts per step makes the Coulomb friction's
    sign flicker at every reversal (again taken for damping: B̂ came out twice the
    truth on the bench). Offline the whole record is known, so the velocity is taken
    instead as the derivative of the angle smoothed without lag (Butterworth, forward
    and backward, at ``VELOCITY_SMOOTHING · g_dist``). The record says which was used.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``, a constant step.
    i_a : ndarray
        Current (A), shape ``(N,)``: the current that acted over the step ending at
        each sample (the timing contract).
    omega_m : ndarray
        Motor velocity (rad/s), shape ``(N,)``.
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.
    actuator : Actuator
        The motor's terms (J_mo kg·m², k_to N·m/A, friction).
    g_dist : float
        Bandwidth of the disturbance observer (rad/s).

    Returns
    -------
    MotorRecord
        The step (s), the motor angle (rad) and τ̂_reac (N·m, shape ``(N,)``), with
        ``g_dist`` and where the velocity came from.

    Raises
    ------
    IdentificationError
        A log with fewer than 3 samples or a varying step, or a reaction torque beyond
        :data:`MAX_TORQUE` (actuator terms in the wrong units, say).

    Examples
    --------
    >>> import dataclasses
    >>> run = arcosim.run_scenario(dataclasses.replace(arcosim.SCENARIOS["flexible"], duration=1.0))
    >>> signals = [run[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")]
    >>> motor = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406, D_m=2e-5, f_c=2e-3)
    >>> record = arcosim.motor_record(run.time, *signals, motor, 100.0)
    >>> record.h, record.tau_hat.shape
    (0.001, (1001,))
    """
    h = constant_step(time)
    velocity = np.asarray(omega_m, dtype=float)
    source = "measured"
    if is_backward_difference(theta_m, velocity, h):
        velocity = smooth_velocity(theta_m, h, VELOCITY_SMOOTHING * g_dist)
        source = (
            f"derivative of theta_m smoothed at {VELOCITY_SMOOTHING * g_dist:g} rad/s without lag "
            "(the log's omega_m is its backward difference)"
        )
    dob = ReactionObserver(actuator, g_dist, float(theta_m[0]), float(velocity[0]))
    tau = np.zeros(len(time))
    step = dob.step
    for k, (i, w, th) in enumerate(zip(i_a.tolist(), velocity.tolist(), theta_m.tolist())):
        if k:
            step(h, i, w, th)
            tau[k] = dob.tau_reac_hat
    peak = float(np.max(np.abs(tau))) if tau.size else 0.0
    if not peak <= MAX_TORQUE:
        raise IdentificationError(
            f"the log's reaction torque through the actuator terms reaches {peak:.3g} N·m "
            f"(at most {MAX_TORQUE:g}): check J_m, k_t, g_dist and the units of the log's "
            "columns"
        )
    return MotorRecord(h, np.asarray(theta_m, dtype=float), tau, g_dist, source, velocity)


def is_backward_difference(theta_m: np.ndarray, omega_m: np.ndarray, h: float) -> bool:
    """True when ``omega_m[k] = (theta_m[k] − theta_m[k−1]) / h`` for every k ≥ 1
    (angle in rad and velocity in rad/s, shape ``(N,)``; ``h`` in s)."""
    diff = np.diff(theta_m) / h
    scale = max(float(np.max(np.abs(diff))), 1e-12)
    return bool(np.max(np.abs(omega_m[1:] - diff)) <= 1e-9 * scale)


def smooth_velocity(theta_m: np.ndarray, h: float, cutoff: float) -> np.ndarray:
    """Derivative (rad/s, shape ``(N,)``) of the angle ``theta_m`` (rad, shape ``(N,)``,
    step ``h`` in s) low-passed at ``cutoff`` (rad/s) forward and backward (2nd-order
    Butterworth each way: no lag, 4th-order roll-off)."""
    return np.gradient(low_passed(np.asarray(theta_m, dtype=float), h, cutoff), h)


def motor_opening(record: MotorRecord, seconds: float) -> MotorRecord:
    """The first ``seconds`` (s) of ``record`` (the whole record if it is shorter)."""
    count = min(len(record.theta_m), round(seconds / record.h) + 1)
    return MotorRecord(
        record.h,
        record.theta_m[:count],
        record.tau_hat[:count],
        record.g_dist,
        record.velocity_source,
        None if record.velocity is None else record.velocity[:count],
    )


#: Floor of the process noise's standard deviation (N·m per step).
TORQUE_STD_FLOOR = 1e-4

#: Load choices: none, a constant torque, or a constant plus a slow random walk.
LOADS = ("none", "constant", "slow")

#: Friction forms a fit of an unknown friction may carry (viscous: D_m, Coulomb: f_c).
FRICTION_FORMS = ("none", "viscous", "coulomb", "both")

#: Random walk of a ``"slow"`` load (N·m per √s), relative to the rms drive torque.
LOAD_DRIFT = 0.05


@dataclass(frozen=True)
class EncoderRecord:
    """The drive's own signals for the prediction-error fit.

    Attributes
    ----------
    h : float
        Sample step (s).
    drive : ndarray
        ``k_t i_a`` over the step ending at each sample (N·m), shape ``(N,)``.
    velocity : ndarray
        Motor velocity whose sign sets the Coulomb friction's (rad/s), shape ``(N,)``.
    theta_m : ndarray
        Encoder angle at the middle of its count (rad), shape ``(N,)``.
    count : float
        One encoder count (rad).
    J_m : float
        Motor inertia (kg·m²).
    D_m : float
        Motor viscous friction (N·m·s/rad): given, or the fit's start.
    f_c : float
        Motor Coulomb friction (N·m): given, or the fit's start.
    torque_std : float
        Process noise (N·m per step).
    friction_given : bool
        D_m and f_c are known; else they are fitted.
    load : str
        One of :data:`LOADS`.
    load_std : float
        Random walk of a ``"slow"`` load (N·m per step).
    friction_sign : ndarray or None
        s_k over each step (−1 … 1, dimensionless), shape ``(N,)``; None: sgn(velocity).
    friction_form : str
        Which of D_m, f_c a fit of an unknown friction carries (one of
        :data:`FRICTION_FORMS`); the others stay at their value here (0).
    """

    h: float
    drive: np.ndarray
    velocity: np.ndarray
    theta_m: np.ndarray
    count: float
    J_m: float
    D_m: float
    f_c: float
    torque_std: float
    friction_given: bool = True
    load: str = "none"
    load_std: float = 0.0
    friction_sign: np.ndarray | None = None
    friction_form: str = "both"

    @property
    def sign(self) -> np.ndarray:
        """s_k (−1 … 1) over the step ending at sample k, shape (N,): given, or the
        mean of sgn ω over the step with ω linear between samples (:func:`mean_sign`)."""
        return mean_sign(self.velocity) if self.friction_sign is None else self.friction_sign

    @property
    def torque(self) -> np.ndarray:
        """``k_t i_a − f_c s_k`` (N·m), shape (N,)."""
        return self.drive - self.f_c * self.sign

    @property
    def duration(self) -> float:
        """Record length (s)."""
        return self.h * (len(self.theta_m) - 1)


def encoder_record(
    time: np.ndarray,
    i_a: np.ndarray,
    theta_m: np.ndarray,
    actuator: Actuator,
    cpr: int,
    friction_given: bool = True,
    load: str = "none",
    g_dist: float = G_DIST,
) -> EncoderRecord:
    """The record of the prediction-error fit: the current in, the encoder's counts out.

    The friction's sign comes from the angle's derivative smoothed without lag at
    ``VELOCITY_SMOOTHING · g_dist``, as the motor record's DOB velocity (the second
    pass of :func:`~arcosim.identification.fit.encoder_fit.refine` replaces it). With
    ``friction_given=False`` the actuator's D_m, f_c are ignored and the fit starts from
    a rigid-body estimate (:func:`rigid_friction`).

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``, a constant step.
    i_a : ndarray
        Current (A), shape ``(N,)``, the current that acted over each step.
    theta_m : ndarray
        Motor angle as the encoder gives it (rad, whole counts), shape ``(N,)``.
    actuator : Actuator
        The motor's terms (J_mo kg·m², k_to N·m/A, D_m N·m·s/rad, f_c N·m).
    cpr : int
        The encoder's counts per revolution (a count), > 0.
    friction_given : bool
        Whether the actuator's D_m and f_c are known (else they are fitted).
    load : {"none", "constant", "slow"}
        The load torque the model carries on the last mass.
    g_dist : float
        The DOB's bandwidth (rad/s), for the friction sign's smoothing.

    Returns
    -------
    EncoderRecord
        The drive torque (N·m), the counts' angle (rad) and their resolution (rad),
        the friction model and its start, each array of shape ``(N,)``.

    Raises
    ------
    IdentificationError
        For an encoder without counts (``cpr`` ≤ 0), a varying step or an unknown
        ``load``.

    Examples
    --------
    >>> t = np.arange(1000) * 1e-3
    >>> counts = 2.0 * np.pi / 2000
    >>> theta = np.floor(np.sin(3.0 * t) / counts) * counts
    >>> motor = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406)
    >>> record = arcosim.encoder_record(t, 0.1 * np.sin(3.0 * t), theta, motor, 2000)
    >>> record.h, float(record.count) == counts
    (0.001, True)
    """
    if cpr <= 0:
        raise IdentificationError(
            "the prediction-error fit needs the encoder's counts per revolution"
        )
    if load not in LOADS:
        raise IdentificationError(f"load must be one of {', '.join(LOADS)}, got {load!r}")
    h = constant_step(time)
    count = 2.0 * np.pi / cpr
    theta = np.asarray(theta_m, dtype=float) + count / 2.0
    drive = (actuator.k_to + actuator.dkt) * np.asarray(i_a, dtype=float)
    cutoff = VELOCITY_SMOOTHING * g_dist
    velocity = smooth_velocity(theta, h, cutoff)
    J_m = actuator.J_mo + actuator.dJm
    D_m, f_c = actuator.D_m, actuator.f_c
    if not friction_given:
        D_m, f_c = rigid_friction(drive, theta, velocity, h)
    drift = LOAD_DRIFT * float(np.sqrt(np.mean(drive**2))) * np.sqrt(h)
    return EncoderRecord(
        h=h,
        drive=drive,
        velocity=velocity,
        theta_m=theta,
        count=count,
        J_m=J_m,
        D_m=D_m,
        f_c=f_c,
        torque_std=torque_std(f_c),
        friction_given=friction_given,
        load=load,
        load_std=drift if load == "slow" else 0.0,
    )


def encoder_opening(record: EncoderRecord, seconds: float) -> EncoderRecord:
    """The first ``seconds`` (s) of ``record`` (all of it if shorter)."""
    count = min(len(record.theta_m), round(seconds / record.h) + 1)
    sign = None if record.friction_sign is None else record.friction_sign[:count]
    return replace(
        record,
        drive=record.drive[:count],
        velocity=record.velocity[:count],
        theta_m=record.theta_m[:count],
        friction_sign=sign,
    )


def rigid_friction(
    drive: np.ndarray, theta: np.ndarray, velocity: np.ndarray, h: float
) -> tuple[float, float]:
    """Start values ``(D_m, f_c)`` from the record read as one rigid body: below a
    few rad/s the chain moves with the motor, so ``k_t i ≈ J_total α + D_m ω + f_c sgn ω``;
    least squares on the signals low-passed at 2 rad/s (J_total fitted too); sgn ω from
    the record's smoothed ``velocity`` (rad/s)."""
    cutoff = 2.0
    b, a = signal.butter(2, min(cutoff * h / np.pi, 0.5))
    torque = signal.filtfilt(b, a, drive)
    angle = signal.filtfilt(b, a, theta)
    omega = np.gradient(angle, h)
    alpha = np.gradient(omega, h)
    sign = signal.filtfilt(b, a, np.sign(velocity))
    X = np.column_stack([alpha, omega, sign])
    coef = np.linalg.lstsq(X, torque, rcond=None)[0]
    scale = float(np.sqrt(np.mean(drive**2)))
    D_m = float(np.clip(coef[1], 1e-6 * scale, None))
    f_c = float(np.clip(coef[2], 1e-3 * scale, None))
    return D_m, f_c


def mean_sign(velocity: np.ndarray) -> np.ndarray:
    """Mean of sgn ω over each step ending at a sample, ω linear between samples (a
    reversal inside a step counts for the fraction of the step on each side); sample 0
    takes its own sign. Shape (N,)."""
    w0, w1 = velocity[:-1], velocity[1:]
    s0, s1 = np.sign(w0), np.sign(w1)
    out = np.sign(s0 + s1)  # no reversal: the sign of the end that moves (0 if neither)
    cross = s0 * s1 < 0
    r = w0[cross] / (w0[cross] - w1[cross])  # fraction of the step before the reversal
    out[cross] = s0[cross] * (2.0 * r - 1.0)
    return np.concatenate([[np.sign(velocity[0])], out])


def torque_std(f_c: float) -> float:
    """Unmodelled motor torque (N·m per step): half the Coulomb friction ``f_c`` (N·m;
    what the friction model misses while the motor sticks), at least
    :data:`TORQUE_STD_FLOOR`."""
    return max(f_c / 2.0, TORQUE_STD_FLOOR)


def with_friction(record: EncoderRecord, D_m: float, f_c: float) -> EncoderRecord:
    """``record`` with the motor friction ``D_m`` (N·m·s/rad), ``f_c`` (N·m) and the
    process noise that goes with it (:func:`torque_std`)."""
    return replace(record, D_m=D_m, f_c=f_c, torque_std=torque_std(f_c))
