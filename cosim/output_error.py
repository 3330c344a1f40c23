"""Output-error identification of the load chain from a motor-side log (offline).

The load chain, driven by the measured motor angle (linear between samples), predicts
the reaction torque; the prediction goes through the DOB's own ``G(s)`` and is fitted to
the reaction torque observer's estimate τ̂_reac computed from the same log
(:class:`flexchain.dob.ReactionObserver`, the code the observer FMU runs). The chain
model is :mod:`flexchain.driven_chain`, shared with the model-based observer; here it is
simulated in modal coordinates with ``scipy.signal.lfilter`` (no Python loop per sample).

Two parameterizations share one fit (:func:`fit`):

* the paper's uniform chain: k and B common to every spring, J_i known (optionally a
  common scale on the J_i) — :func:`uniform_chain`;
* the whole chain: every J_i, k_i, B_i (``cosim/whole_chain.py``).

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

from cosim.errors import UserError
from flexchain.chain import spring_matrix
from flexchain.dob import Actuator, ReactionObserver
from flexchain.driven_chain import discretize


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


def constant_step(time: np.ndarray, what: str = "the log") -> float:
    """The step of a uniformly sampled time column (s).

    Raises:
        UserError: if the step varies by more than 1e-6 of its mean.
    """
    steps = np.diff(np.asarray(time, dtype=float))
    if len(steps) < 2:
        raise UserError(f"{what} has fewer than 3 samples; output-error needs a record")
    h = float(np.mean(steps))
    if np.max(np.abs(steps - h)) > 1e-6 * h:
        raise UserError(
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
    """Run the reaction torque observer over a log (timing contract of METHOD.md).

    When the log's velocity is the encoder's backward difference (a realistic drive,
    and the plant FMU with an encoder), two things go wrong offline that need not:
    the DOB's pairing of the velocity change with the step's current is off by half a
    step (J_m·α lags by h/2, an error in quadrature that the fit takes for damping),
    and a velocity that jumps by whole counts per step makes the Coulomb friction's
    sign flicker at every reversal (an error with the sign of the velocity, again
    taken for damping: B̂ came out twice the truth on the bench). Offline the whole
    record is known, so the velocity is taken instead as the derivative of the angle
    smoothed without lag (Butterworth, forward and backward, at ``4 g_dist``, where
    G(s) has already removed most of what it cuts). The record says which was used.
    """
    h = constant_step(time)
    velocity = np.asarray(omega_m, dtype=float)
    source = "measured"
    if is_backward_difference(theta_m, velocity, h):
        velocity = smooth_velocity(theta_m, h, 4.0 * g_dist)
        source = (
            f"derivative of theta_m smoothed at {4.0 * g_dist:g} rad/s without lag "
            "(the log's omega_m is its backward difference)"
        )
    dob = ReactionObserver(actuator, g_dist, float(theta_m[0]), float(velocity[0]))
    tau = np.zeros(len(time))
    step = dob.step
    for k, (i, w, th) in enumerate(zip(i_a.tolist(), velocity.tolist(), theta_m.tolist())):
        if k:
            step(h, i, w, th)
            tau[k] = dob.tau_reac_hat
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
    lam, V = np.linalg.eig(Ad)
    forcing = np.linalg.solve(V, Bd.astype(complex)) @ w
    modal = np.empty_like(forcing)
    for j, root in enumerate(lam):
        modal[j] = signal.lfilter([1.0], [1.0, -root], forcing[j])
    x_after = (V @ modal).real  # x_1 … x_{N−1}
    x_before = np.hstack([np.zeros((len(c), 1)), x_after[:, :-1]])
    torque = c @ x_before + d @ w
    a = np.exp(-record.g_dist * record.h)
    filtered = signal.lfilter([1.0 - a], [1.0, -a], torque)
    return np.concatenate([[0.0], filtered])


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
        raise UserError(f"output-error start values must be finite and > 0, got {start}")
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
    """Bandwidth (samples) for the long-run covariance.

    Three times the lag where the residual's autocorrelation first falls below 0.1,
    and at least five time constants of G(s); at most a tenth of the record.
    """
    r = residual - residual.mean()
    n = len(r)
    spectrum = np.fft.rfft(r, 2 * n)
    acf = np.fft.irfft(spectrum * np.conj(spectrum))[:n]
    acf = acf / max(acf[0], 1e-300)
    below = np.flatnonzero(np.abs(acf) < 0.1)
    first = int(below[0]) if below.size else n
    floor = int(np.ceil(5.0 / (record.g_dist * record.h)))
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


def resonance_peaks(record: MotorRecord, count: int, band: tuple[float, float]) -> np.ndarray:
    """Frequencies (rad/s) of the ``count`` strongest peaks of ``|τ̂ / θ_m|``.

    The driving-point response of the load chain (motor angle in, reaction torque
    out) peaks at the chain's natural frequencies with the motor held still. Welch
    estimate (Hann windows of a quarter of the record), peaks refined by a parabola
    through the log-magnitude. Returns no peak for a record without torque or motion.
    """
    fs = 1.0 / record.h
    nper = min(len(record.theta_m), max(256, len(record.theta_m) // 4))
    f, s_uy = signal.csd(record.theta_m, record.tau_hat, fs=fs, nperseg=nper, detrend="linear")
    _, s_uu = signal.welch(record.theta_m, fs=fs, nperseg=nper, detrend="linear")
    w = 2 * np.pi * f
    mag = np.log(np.abs(s_uy) / np.maximum(s_uu, 1e-300) + 1e-300)
    inside = (w >= band[0]) & (w <= band[1])
    if not np.any(record.tau_hat) or np.ptp(record.theta_m) == 0.0:
        return np.array([])
    peaks, props = signal.find_peaks(np.where(inside, mag, -np.inf), prominence=0.5)
    if peaks.size == 0:
        return np.array([])
    order = np.argsort(props["prominences"])[::-1][:count]
    found = []
    for p in peaks[order]:
        if 0 < p < len(mag) - 1:
            y0, y1, y2 = mag[p - 1 : p + 2]
            shift = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2) if (y0 - 2 * y1 + y2) != 0 else 0.0
            found.append(w[p] + shift * (w[1] - w[0]))
        else:
            found.append(w[p])
    return np.sort(np.array(found))


def uniform_chain(
    record: MotorRecord,
    J: Sequence[float],
    fit_inertia_scale: bool = False,
    k_start: float | None = None,
    zeta_start: float = 1e-3,
) -> Fit:
    """Fit the paper's uniform chain: common k and B (and a common scale on the J_i).

    Start: ``k_start`` if given, else from the lowest resonance of the data (the
    first clamped mode of a uniform chain scales as √k), refined by a scan of the cost
    over k from 0.3 to 3 times that (the cost has local minima); B from
    ``zeta_start`` on the first mode.

    Raises:
        UserError: when the data show no resonance and no ``k_start`` is given.
    """
    J = [float(x) for x in J]
    unit = clamped_frequencies(J, [1.0] * len(J))  # frequencies at k = 1
    if k_start is None:
        peaks = resonance_peaks(record, len(J), (0.5 * np.pi / record.duration, 0.3 / record.h))
        if peaks.size == 0:
            raise UserError(
                "the log shows no resonance of the chain: excite it (a multi-sine or chirp "
                "across the modes, see `arcosim simulate --scenario flexible`) or give a start "
                "with --start-k"
            )
        k_peak = (peaks[0] / unit[0]) ** 2
        scan = k_peak * np.geomspace(0.3, 3.0, 41)
        costs = [
            float(
                np.sum(
                    (
                        predict(record, J, [kk] * len(J), [_damping(kk, J, zeta_start)] * len(J))
                        - record.tau_hat
                    )
                    ** 2
                )
            )
            for kk in scan
        ]
        k0 = float(scan[int(np.argmin(costs))])
        note = (
            f"resonance at {peaks[0]:.3g} rad/s (k = {k_peak:.4g} N.m/rad), refined by a "
            f"scan of the cost: k = {k0:.4g} N.m/rad"
        )
    else:
        k0, note = float(k_start), f"given: k = {k_start:.4g} N.m/rad"
    B0 = _damping(k0, J, zeta_start)
    names = ["k", "B"]
    start = [k0, B0]
    lower = [1e-3 * k0, 0.0]
    if fit_inertia_scale:
        names.append("J_scale")
        start.append(1.0)
        lower.append(1e-2)

    def model(p: np.ndarray) -> tuple[list[float], list[float], list[float]]:
        scale = p[2] if fit_inertia_scale else 1.0
        n = len(J)
        return [scale * x for x in J], [p[0]] * n, [p[1]] * n

    return fit(record, names, np.array(start), model, note, np.array(lower))


def _damping(k: float, J: Sequence[float], zeta: float) -> float:
    """Uniform B giving damping ratio ``zeta`` on the first clamped mode of a uniform chain."""
    w1 = float(clamped_frequencies(J, [k] * len(J))[0])
    return 2.0 * zeta * k / w1
