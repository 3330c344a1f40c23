"""Output-error identification of the load chain from a motor-side log (offline).

The load chain, driven by the measured motor angle (linear between samples), predicts
the reaction torque; the prediction goes through the DOB's own ``G(s)`` and is fitted to
the reaction torque observer's estimate τ̂_reac computed from the same log
(:class:`arcosim.fmu.flexchain.dob.ReactionObserver`, the code the observer FMU runs). The chain
model is :mod:`arcosim.fmu.flexchain.driven_chain`, shared with the model-based observer; here it is
simulated in modal coordinates with ``scipy.signal.lfilter`` (no Python loop per sample).

Two parameterizations share one fit (:func:`fit`):

* the paper's uniform chain: k and B common to every spring, J_i known (optionally a
  common scale on the J_i) — :func:`uniform_chain`;
* the whole chain: every J_i, k_i, B_i (``cosim/whole_chain.py``, started from the
  record's modes, ``cosim/modal_start.py``).

Standard errors come from a Newey–West (Bartlett) long-run covariance of the score
``J_t r_t``: the residuals are low-passed by G(s) and coloured by the chain, so the
textbook ``σ² (JᵀJ)⁻¹`` would be far too optimistic.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
from scipy import optimize, signal

from arcosim.fmu.flexchain.chain import spring_matrix
from arcosim.fmu.flexchain.defaults import VELOCITY_SMOOTHING
from arcosim.fmu.flexchain.dob import Actuator, ReactionObserver
from arcosim.fmu.flexchain.driven_chain import discretize
from arcosim.fmu.flexchain.filters import lowpass_pole
from arcosim.identification.blas import single_threaded
from arcosim.identification.errors import IdentificationError


@dataclass(frozen=True)
class MotorRecord:
    """A motor-side record ready for fitting.

    Attributes:
        h: the (constant) step (s).
        theta_m: measured motor angle at each sample (rad), shape (N,).
        tau_hat: τ̂_reac after each sample (N·m), shape (N,); sample 0 is the start.
        g_dist: the DOB bandwidth used for ``tau_hat`` (rad/s).
        velocity_source: which motor velocity the DOB was given.
    """

    h: float
    theta_m: np.ndarray
    tau_hat: np.ndarray
    g_dist: float
    velocity_source: str = "measured"

    @property
    def duration(self) -> float:
        """Record length (s)."""
        return self.h * (len(self.theta_m) - 1)


#: Largest reaction torque (N·m) a record may carry: far beyond any drive, and small
#: enough that the fits' sums of squares over 10⁷ samples stay finite.
MAX_TORQUE = 1e100


def through_g(x: np.ndarray, g: float, h: float) -> np.ndarray:
    """``x`` (shape ``(N,)``, any unit) through the DOB's ``G(s) = g / (s + g)`` (g in
    rad/s) at a constant step ``h`` (s), held input: the FMU's own discretization
    (:func:`~arcosim.fmu.flexchain.filters.lowpass_pole`)."""
    a = lowpass_pole(g, h)
    return signal.lfilter([1.0 - a], [1.0, -a], x)


def constant_step(time: np.ndarray, what: str = "the log") -> float:
    """The step of a uniformly sampled time column (s).

    Raises:
        IdentificationError: if the step varies by more than 1e-6 of its mean.
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
    return MotorRecord(h, np.asarray(theta_m, dtype=float), tau, g_dist, source)


def is_backward_difference(theta_m: np.ndarray, omega_m: np.ndarray, h: float) -> bool:
    """True when ``omega_m[k] = (theta_m[k] − theta_m[k−1]) / h`` for every k ≥ 1."""
    diff = np.diff(theta_m) / h
    scale = max(float(np.max(np.abs(diff))), 1e-12)
    return bool(np.max(np.abs(omega_m[1:] - diff)) <= 1e-9 * scale)


def smooth_velocity(theta_m: np.ndarray, h: float, cutoff: float) -> np.ndarray:
    """Derivative (rad/s) of the angle low-passed at ``cutoff`` (rad/s) forward and
    backward (2nd-order Butterworth each way: no lag, 4th-order roll-off)."""
    theta = np.asarray(theta_m, dtype=float)
    nyquist = np.pi / h
    if cutoff < nyquist and len(theta) > 12:
        b, a = signal.butter(2, cutoff / nyquist)
        theta = signal.filtfilt(b, a, theta)
    return np.gradient(theta, h)


def _expm(a: list[list[float]]) -> list[list[float]]:
    return scipy.linalg.expm(np.asarray(a)).tolist()


def predict(
    record: MotorRecord, J: Sequence[float], k: Sequence[float], B: Sequence[float]
) -> np.ndarray:
    """τ̂_reac the chain (J, k, B) would give on ``record``'s motor angle (N·m), shape (N,).

    The chain starts at rest, aligned with the motor (as the observer assumes).
    """
    chain = discretize(J, k, B, record.h, expm=_expm)
    Ad, Bd = np.asarray(chain.Ad), np.asarray(chain.Bd)
    c, d = (np.asarray(r) for r in chain.torque_row())
    u = record.theta_m - record.theta_m[0]  # a common offset of all angles is an equilibrium
    w = np.vstack([u[:-1], np.diff(u) / record.h])  # inputs of steps 1 … N−1
    x = linear_recursion(Ad, Bd, w, np.zeros(len(c)))  # x_0 … x_{N−1}
    torque = c @ x[:, :-1] + d @ w
    return np.concatenate([[0.0], through_g(torque, record.g_dist, record.h)])


def linear_recursion(F: np.ndarray, G: np.ndarray, u: np.ndarray, first: np.ndarray) -> np.ndarray:
    """``x_0 = first``, ``x_{j+1} = F x_j + G u_j``, in modal coordinates with ``lfilter``
    (no Python loop per sample).

    Args:
        F: state matrix, shape (S, S), diagonalizable.
        G: input matrix, shape (S, I).
        u: inputs, shape (I, M).
        first: x_0, shape (S,).

    Returns:
        x_0 … x_M as columns, shape (S, M + 1).
    """
    lam, V = np.linalg.eig(F)
    forcing = np.linalg.solve(V, np.asarray(G, dtype=complex)) @ u
    modal_first = np.linalg.solve(V, first.astype(complex))
    modal = np.empty((len(lam), u.shape[1] + 1), dtype=complex)
    modal[:, 0] = modal_first
    for j, root in enumerate(lam):
        modal[j, 1:], _ = signal.lfilter(
            [1.0], [1.0, -root], forcing[j], zi=[root * modal_first[j]]
        )
    return (V @ modal).real


@dataclass
class Fit:
    """Result of :func:`fit`.

    Attributes:
        names: parameter names.
        values: estimates.
        std: standard errors (Newey–West), same order.
        start: the starting values.
        start_note: where the start came from.
        rms_residual: rms of τ̂_model − τ̂_reac (N·m).
        rms_data: rms of τ̂_reac (N·m).
        lag: Newey–West bandwidth (samples).
        evaluations: model simulations used by the optimizer.
        extra: method-specific evidence (JSON-able).
    """

    names: list[str]
    values: np.ndarray
    std: np.ndarray
    start: np.ndarray
    start_note: str
    rms_residual: float
    rms_data: float
    lag: int
    evaluations: int
    extra: dict = field(default_factory=dict)

    def as_dict(self) -> dict[str, float]:
        """Estimates by name."""
        return {n: float(v) for n, v in zip(self.names, self.values)}

    def std_dict(self) -> dict[str, float]:
        """Standard errors by name."""
        return {n: float(s) for n, s in zip(self.names, self.std)}


def fit(
    record: MotorRecord,
    names: Sequence[str],
    start: np.ndarray,
    model: Callable[[np.ndarray], tuple[list[float], list[float], list[float]]],
    start_note: str,
    lower: np.ndarray | None = None,
) -> Fit:
    """Least-squares fit of parameters ``p`` (``model(p) → (J, k, B)``) to τ̂_reac.

    The optimizer works on ``p / start`` so every parameter is of order one.

    Args:
        record: the data.
        names: parameter names, len P.
        start: starting values (> 0), shape (P,).
        model: maps a parameter vector to the chain.
        start_note: where ``start`` came from (reported).
        lower: lower bounds (default: a thousandth of ``start``; pass 0 for a damping).
    """
    start = np.asarray(start, dtype=float)
    if np.any(~np.isfinite(start)) or np.any(start <= 0):
        raise IdentificationError(f"output-error start values must be finite and > 0, got {start}")
    lower = 1e-3 * start if lower is None else np.asarray(lower, dtype=float)
    data = record.tau_hat

    def residual(scaled: np.ndarray) -> np.ndarray:
        return predict(record, *model(scaled * start)) - data

    result = optimize.least_squares(
        residual,
        np.ones_like(start),
        bounds=(lower / start, np.inf),
        x_scale="jac",
        diff_step=1e-6,
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-12,
        max_nfev=200,
    )
    values = result.x * start
    jac = result.jac / start  # d r / d p
    lag = newey_west_lag(result.fun, record)
    cov = newey_west_covariance(jac, result.fun, lag)
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return Fit(
        names=list(names),
        values=values,
        std=std,
        start=start,
        start_note=start_note,
        rms_residual=float(np.sqrt(np.mean(result.fun**2))),
        rms_data=float(np.sqrt(np.mean(data**2))),
        lag=lag,
        evaluations=int(result.nfev + result.njev * len(start)),
    )


def newey_west_lag(residual: np.ndarray, record: MotorRecord) -> int:
    """Bandwidth (samples) for the long-run covariance: :func:`decorrelation_lag`
    with a floor of five time constants of G(s)."""
    return decorrelation_lag(residual, int(np.ceil(5.0 / (record.g_dist * record.h))))


def decorrelation_lag(residual: np.ndarray, floor: int) -> int:
    """Three times the lag where the residual's autocorrelation first falls below 0.1,
    at least ``floor`` and at most a tenth of the record (samples)."""
    r = residual - residual.mean()
    n = len(r)
    spectrum = np.fft.rfft(r, 2 * n)
    acf = np.fft.irfft(spectrum * np.conj(spectrum))[:n]
    acf = acf / max(acf[0], 1e-300)
    below = np.flatnonzero(np.abs(acf) < 0.1)
    first = int(below[0]) if below.size else n
    return int(min(max(3 * first, floor), n // 10))


def newey_west_covariance(jac: np.ndarray, residual: np.ndarray, lag: int) -> np.ndarray:
    """``(JᵀJ)⁻¹ S (JᵀJ)⁻¹`` with S the Bartlett-weighted long-run covariance of
    the score ``J_t r_t`` (shape (P, P))."""
    score = jac * residual[:, None]
    S = score.T @ score
    for lag_k in range(1, lag + 1):
        gamma = score[lag_k:].T @ score[:-lag_k]
        S += (1.0 - lag_k / (lag + 1.0)) * (gamma + gamma.T)
    bread = np.linalg.pinv(jac.T @ jac)
    return bread @ S @ bread


def clamped_frequencies(J: Sequence[float], k: Sequence[float]) -> np.ndarray:
    """Natural frequencies (rad/s) of the load chain with the motor held still."""
    K = np.array(spring_matrix(k))[1:, 1:]  # motor row and column removed: held still
    return np.sqrt(np.sort(np.linalg.eigvals(K / np.asarray(J)[:, None]).real))


#: Length (s) of the record's opening the start scan runs on: the cost's basin around the
#: truth narrows as the record grows (a mode's phase error grows as δω·t), so the scan
#: and the first fit use a short opening and :func:`continued_fit` lengthens it.
SCAN_SECONDS = 2.5
#: Damping ratio of the first clamped mode for the scan's chains.
SCAN_ZETA = 1e-3


def opening(record: MotorRecord, seconds: float) -> MotorRecord:
    """The first ``seconds`` of ``record`` (the whole record if it is shorter)."""
    count = min(len(record.theta_m), round(seconds / record.h) + 1)
    return MotorRecord(
        record.h,
        record.theta_m[:count],
        record.tau_hat[:count],
        record.g_dist,
        record.velocity_source,
    )


def check_excited(record: MotorRecord) -> None:
    """Refuse a record whose motor never moved or whose reaction torque never changed.

    Raises:
        IdentificationError: naming what is missing and what to do.
    """
    if not np.any(record.tau_hat) or np.ptp(record.theta_m) == 0.0:
        raise IdentificationError(
            "the log shows no resonance of the chain (its reaction torque or motor angle "
            "never changes): excite it (a multi-sine or chirp across the modes, see "
            "`arcosim simulate --scenario flexible`) or give a start with --start-k"
        )


def scan_first_mode(
    record: MotorRecord,
    chain_at: Callable[[float], tuple[list[float], list[float], list[float]]],
    count: int = 100,
) -> tuple[float, str]:
    """Pick the chain whose first clamped mode best explains the record's opening.

    ``chain_at(w1)`` gives the chain whose first clamped mode is ``w1`` (rad/s); ``w1``
    runs over ``count`` log-spaced values from 2 rad/s to 0.3/h (the band G(s) and the
    sample rate leave).

    Returns:
        ``(w1, note)``: the best first mode (rad/s) and a line for the report.
    """
    check_excited(record)
    short = opening(record, SCAN_SECONDS)
    data = short.tau_hat
    best = (np.inf, 0.0)
    for w1 in np.geomspace(2.0, 0.3 / record.h, count):
        cost = float(np.sum((data - predict(short, *chain_at(float(w1)))) ** 2))
        if cost < best[0]:
            best = (cost, float(w1))
    w1 = best[1]
    note = (
        f"scan of the cost over the first clamped mode (2 … {0.3 / record.h:.0f} rad/s) on "
        f"the first {short.duration:g} s: {w1:.4g} rad/s"
    )
    return w1, note


def continued_fit(
    record: MotorRecord,
    names: Sequence[str],
    start: np.ndarray,
    model: Callable[[np.ndarray], tuple[list[float], list[float], list[float]]],
    start_note: str,
    lower: Callable[[np.ndarray], np.ndarray],
) -> Fit:
    """:func:`fit` on the record's opening of :data:`SCAN_SECONDS`, then on openings
    twice as long, each starting from the last, up to the whole record.

    A lightly damped chain's cost has local minima spaced by about π / T in each mode's
    frequency (T the record length), so a start good enough for a short record may not
    be for a long one; the short fit moves it into the long record's basin.
    ``lower(start)`` gives each stage's lower bounds. A parameter that fell below a
    thousandth of its first start (a damping at its bound 0) restarts the next stage
    from there (the fit's start must be > 0).
    """
    first = start = np.asarray(start, dtype=float)
    floor = 1e-3 * start
    seconds = SCAN_SECONDS
    while True:
        part = opening(record, seconds)
        result = fit(part, names, start, model, start_note, lower(start))
        if part.duration >= record.duration:
            result.start = first
            return result
        start = np.maximum(result.values, floor)
        seconds *= 2.0


@single_threaded
def uniform_chain(
    record: MotorRecord,
    J: Sequence[float],
    fit_inertia_scale: bool = False,
    k_start: float | None = None,
    zeta_start: float = SCAN_ZETA,
) -> Fit:
    """Fit the paper's uniform chain by output error: one k and one B for every spring.

    Start: ``k_start`` if given, else :func:`scan_first_mode` (the first clamped mode
    of a uniform chain scales as √k); B from ``zeta_start`` on the first mode. The fit
    then runs on longer and longer openings of the record (:func:`continued_fit`).

    Parameters
    ----------
    record : MotorRecord
        The log's reaction-torque record (:func:`motor_record`).
    J : sequence of float
        The known load inertias J_1 … J_n (kg·m²).
    fit_inertia_scale : bool
        Also fit one common scale on the J_i (dimensionless).
    k_start : float, optional
        Start from this stiffness (N·m/rad) instead of the cost scan.
    zeta_start : float
        Damping ratio of the start's first mode (dimensionless).

    Returns
    -------
    Fit
        ``k`` (N·m/rad) and ``B`` (N·m·s/rad) (and ``J_scale``) with their standard
        errors (Newey–West) and the evidence (start, residual, lag).

    Raises
    ------
    IdentificationError
        When the record shows no motion or no reaction torque.

    Examples
    --------
    >>> import dataclasses
    >>> run = arcosim.run_scenario(dataclasses.replace(arcosim.SCENARIOS["flexible"], duration=5.0))
    >>> signals = [run[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")]
    >>> motor = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406, D_m=2e-5, f_c=2e-3)
    >>> record = arcosim.motor_record(run.time, *signals, motor, 100.0)
    >>> fit = arcosim.uniform_chain(record, [5.15299e-4, 5.15299e-4, 6.192707e-4])
    >>> bool(abs(fit.as_dict()["k"] / 0.1627 - 1.0) < 0.01)  # the bench's k, within 1 %
    True
    """
    J = [float(x) for x in J]
    n = len(J)
    unit = float(clamped_frequencies(J, [1.0] * n)[0])  # first mode at k = 1

    def chain_at(w1: float) -> tuple[list[float], list[float], list[float]]:
        k = (w1 / unit) ** 2
        return J, [k] * n, [2.0 * zeta_start * k / w1] * n

    if k_start is None:
        w1, note = scan_first_mode(record, chain_at)
        k0 = (w1 / unit) ** 2
        note += f" (k = {k0:.4g} N.m/rad)"
    else:
        check_excited(record)
        k0, note = float(k_start), f"given: k = {k_start:.4g} N.m/rad"
    B0 = _damping(k0, J, zeta_start)
    names = ["k", "B"]
    start = [k0, B0]
    if fit_inertia_scale:
        names.append("J_scale")
        start.append(1.0)

    def model(p: np.ndarray) -> tuple[list[float], list[float], list[float]]:
        scale = p[2] if fit_inertia_scale else 1.0
        return [scale * x for x in J], [p[0]] * n, [p[1]] * n

    def lower(p: np.ndarray) -> np.ndarray:
        bounds = [1e-3 * p[0], 0.0]
        return np.array(bounds + ([1e-2] if fit_inertia_scale else []))

    return continued_fit(record, names, np.array(start), model, note, lower)


def _damping(k: float, J: Sequence[float], zeta: float) -> float:
    """Uniform B giving damping ratio ``zeta`` on the first clamped mode of a uniform chain."""
    w1 = float(clamped_frequencies(J, [k] * len(J))[0])
    return 2.0 * zeta * k / w1
