"""The output-error fit every chain fit shares: predict τ̂_reac, fit it (offline).

The load chain, driven by the measured motor angle (linear between samples), predicts
the reaction torque; the prediction goes through the DOB's own ``G(s)``
(:func:`through_g`) and is fitted to the reaction torque observer's estimate τ̂_reac
computed from the same log (:class:`arcosim.identification.records.record.MotorRecord`). The
chain model is :mod:`arcosim.fmu.flexchain.driven_chain`, shared with the model-based
observer; here it is simulated in modal coordinates
(:func:`arcosim.identification.fit.modal_recursion.linear_recursion`: no Python loop per
sample).

:func:`fit` is least squares on that prediction for any parameterization
``p → (J, k, B)``, with Newey–West standard errors
(:mod:`arcosim.identification.fit.newey_west`); :func:`continued_fit` runs it on openings
of growing length. Two parameterizations use it:

* the paper's uniform chain: k and B common to every spring, J_i known (optionally a
  common scale on the J_i) — :func:`arcosim.identification.fit.uniform_fit.uniform_chain`;
* the whole chain: every J_i, k_i, B_i, started from the record's modes
  (:mod:`arcosim.identification.fit.whole_chain`, :mod:`arcosim.identification.modes.detection`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, signal

from arcosim.fmu.flexchain.driven_chain import discretize
from arcosim.fmu.flexchain.filters import lowpass_pole
from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.linear_model import expm
from arcosim.identification.fit.modal_recursion import linear_recursion
from arcosim.identification.fit.newey_west import newey_west_covariance, newey_west_lag
from arcosim.identification.records.record import MotorRecord, motor_opening


def through_g(x: np.ndarray, g: float, h: float) -> np.ndarray:
    """``x`` (shape ``(N,)``, any unit) through the DOB's ``G(s) = g / (s + g)`` (g in
    rad/s) at a constant step ``h`` (s), held input: the FMU's own discretization
    (:func:`~arcosim.fmu.flexchain.filters.lowpass_pole`)."""
    a = lowpass_pole(g, h)
    return signal.lfilter([1.0 - a], [1.0, -a], x)


def predict(
    record: MotorRecord, J: Sequence[float], k: Sequence[float], B: Sequence[float]
) -> np.ndarray:
    """τ̂_reac the chain (J, k, B) would give on ``record``'s motor angle.

    The chain starts at rest, aligned with the motor (as the observer assumes).

    Parameters
    ----------
    record : MotorRecord
        The motor angle (rad), its step (s) and the DOB's ``g_dist`` (rad/s).
    J, k, B : sequence of float
        The load chain: inertias (kg·m²), stiffnesses (N·m/rad), dampings (N·m·s/rad),
        length n each.

    Returns
    -------
    ndarray
        The predicted τ̂_reac (N·m), shape ``(N,)``.
    """
    chain = discretize(J, k, B, record.h, expm=expm)
    Ad, Bd = np.asarray(chain.Ad), np.asarray(chain.Bd)
    c, d = (np.asarray(r) for r in chain.torque_row())
    u = record.theta_m - record.theta_m[0]  # a common offset of all angles is an equilibrium
    w = np.vstack([u[:-1], np.diff(u) / record.h])  # inputs of steps 1 … N−1
    x = linear_recursion(Ad, Bd, w, np.zeros(len(c)))  # x_0 … x_{N−1}
    torque = c @ x[:, :-1] + d @ w
    return np.concatenate([[0.0], through_g(torque, record.g_dist, record.h)])


def rigid_predict(record: MotorRecord, J_load: float) -> np.ndarray:
    """τ̂_reac a load inertia ``J_load`` (kg·m²) rigidly on the motor would give on
    ``record`` (n = 0): ``G[J_load Δω / h]``, with the velocity the DOB was given (its
    own acceleration). Shape ``(N,)``, N·m.

    Raises
    ------
    ValueError
        For a record that did not keep its velocity.
    """
    if record.velocity is None:
        raise ValueError("the rigid drive's τ̂ needs the record's velocity")
    accel = np.concatenate([[0.0], np.diff(record.velocity) / record.h])
    torque = through_g(J_load * accel, record.g_dist, record.h)
    torque[0] = 0.0
    return torque


@dataclass
class ParameterFit:
    """Fitted parameters with their standard errors and the evidence behind them: the
    result of :func:`fit` (and of every chain fit built on it).

    Attributes
    ----------
    names : list of str
        Parameter names, length P (``k``, ``B``, ``J[1]`` …).
    values : ndarray
        Estimates, shape ``(P,)``, each in its parameter's unit (kg·m², N·m/rad,
        N·m·s/rad, N·m).
    std : ndarray
        Standard errors (Newey–West), shape ``(P,)``, same order and units.
    start : ndarray
        The starting values, shape ``(P,)``, same units.
    start_note : str
        Where the start came from (a sentence for the report).
    rms_residual : float
        Rms of τ̂_model − τ̂_reac (N·m).
    rms_data : float
        Rms of τ̂_reac (N·m).
    lag : int
        Newey–West bandwidth (samples).
    evaluations : int
        Model simulations used by the optimizer (a count).
    extra : dict
        Method-specific evidence (JSON-able).

    Examples
    --------
    >>> fit = ParameterFit(["k", "B"], np.array([0.5, 1e-4]), np.array([0.01, 2e-5]),
    ...                    np.array([0.4, 1e-4]), "a guess", 1e-3, 0.1, 5, 40)
    >>> fit.as_dict(), fit.std_dict()["B"]  # N·m/rad, N·m·s/rad
    ({'k': 0.5, 'B': 0.0001}, 2e-05)
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
        """Estimates by name (each in its parameter's unit)."""
        return {n: float(v) for n, v in zip(self.names, self.values)}

    def std_dict(self) -> dict[str, float]:
        """Standard errors by name (each in its parameter's unit)."""
        return {n: float(s) for n, s in zip(self.names, self.std)}


def fit(
    record: MotorRecord,
    names: Sequence[str],
    start: np.ndarray,
    model: Callable[[np.ndarray], tuple[list[float], list[float], list[float]]],
    start_note: str,
    lower: np.ndarray | None = None,
) -> ParameterFit:
    """Least-squares fit of parameters ``p`` (``model(p) → (J, k, B)``) to τ̂_reac.

    The optimizer works on ``p / start`` so every parameter is of order one.

    Parameters
    ----------
    record : MotorRecord
        The data: motor angle (rad) and τ̂_reac (N·m).
    names : sequence of str
        Parameter names, length P.
    start : ndarray
        Starting values (> 0, each in its parameter's unit), shape ``(P,)``.
    model : callable
        Maps a parameter vector (shape ``(P,)``) to the chain ``(J, k, B)`` (kg·m²,
        N·m/rad, N·m·s/rad; lists of length n).
    start_note : str
        Where ``start`` came from (reported).
    lower : ndarray, optional
        Lower bounds, shape ``(P,)`` (default: a thousandth of ``start``; pass 0 for a
        damping).

    Returns
    -------
    ParameterFit
        The estimates with their Newey–West standard errors and the evidence.

    Raises
    ------
    IdentificationError
        For start values that are not finite and > 0.
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
    return ParameterFit(
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


#: Length (s) of the record's opening the start scan runs on: the cost's basin around the
#: truth narrows as the record grows (a mode's phase error grows as δω·t), so the scan
#: and the first fit use a short opening and :func:`continued_fit` lengthens it.
SCAN_SECONDS = 2.5


def check_excited(record: MotorRecord) -> None:
    """Refuse a record whose motor never moved or whose reaction torque never changed.

    Parameters
    ----------
    record : MotorRecord
        The record to look at.

    Raises
    ------
    IdentificationError
        Naming what is missing and what to do.
    """
    if not np.any(record.tau_hat) or np.ptp(record.theta_m) == 0.0:
        raise IdentificationError(
            "the log shows no resonance of the chain (its reaction torque or motor angle "
            "never changes): excite it (a multi-sine or chirp across the modes, see "
            "`arcosim simulate --scenario flexible`) or give a start with --start-k"
        )


def continued_fit(
    record: MotorRecord,
    names: Sequence[str],
    start: np.ndarray,
    model: Callable[[np.ndarray], tuple[list[float], list[float], list[float]]],
    start_note: str,
    lower: Callable[[np.ndarray], np.ndarray],
) -> ParameterFit:
    """:func:`fit` on the record's opening of :data:`SCAN_SECONDS`, then on openings
    twice as long, each starting from the last, up to the whole record.

    A lightly damped chain's cost has local minima spaced by about π / T in each mode's
    frequency (T the record length), so a start good enough for a short record may not
    be for a long one; the short fit moves it into the long record's basin. A parameter
    that fell below a thousandth of its first start (a damping at its bound 0) restarts
    the next stage from there (the fit's start must be > 0).

    Parameters
    ----------
    record, names, start, model, start_note
        As for :func:`fit`.
    lower : callable
        ``lower(start)`` gives each stage's lower bounds (shape ``(P,)``, parameter
        units).

    Returns
    -------
    ParameterFit
        The fit on the whole record, with ``start`` the first stage's.
    """
    first = start = np.asarray(start, dtype=float)
    floor = 1e-3 * start
    seconds = SCAN_SECONDS
    while True:
        part = motor_opening(record, seconds)
        result = fit(part, names, start, model, start_note, lower(start))
        if part.duration >= record.duration:
            result.start = first
            return result
        start = np.maximum(result.values, floor)
        seconds *= 2.0
