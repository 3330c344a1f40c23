"""The paper's uniform chain by output error: one k and one B for every spring (offline).

The load inertias J_1 … J_n are known (optionally up to a common scale); k and B are
fitted to τ̂_reac by the shared output-error fit
(:func:`arcosim.identification.fit.output_error.continued_fit`), started from a scan of
the cost over the chain's first clamped mode (:func:`scan_first_mode`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from arcosim.fmu.flexchain.chain import spring_matrix
from arcosim.identification.excitation.band import sample_band
from arcosim.identification.fit.output_error import (
    SCAN_SECONDS,
    ParameterFit,
    check_excited,
    continued_fit,
    predict,
)
from arcosim.identification.records.record import MotorRecord, motor_opening
from arcosim.identification.threads import single_threaded

#: Damping ratio of the first clamped mode for the scan's chains.
SCAN_ZETA = 1e-3


def clamped_frequencies(J: Sequence[float], k: Sequence[float]) -> np.ndarray:
    """Natural frequencies (rad/s, ascending, shape ``(n,)``) of the load chain of
    inertias ``J`` (kg·m²) and stiffnesses ``k`` (N·m/rad) with the motor held still."""
    K = np.array(spring_matrix(k))[1:, 1:]  # motor row and column removed: held still
    return np.sqrt(np.sort(np.linalg.eigvals(K / np.asarray(J)[:, None]).real))


def scan_first_mode(
    record: MotorRecord,
    chain_at: Callable[[float], tuple[list[float], list[float], list[float]]],
    count: int = 100,
) -> tuple[float, str]:
    """Pick the chain whose first clamped mode best explains the record's opening.

    Parameters
    ----------
    record : MotorRecord
        The record; the scan runs on its first :data:`SCAN_SECONDS`.
    chain_at : callable
        ``chain_at(w1)`` gives the chain ``(J, k, B)`` (kg·m², N·m/rad, N·m·s/rad)
        whose first clamped mode is ``w1`` (rad/s).
    count : int
        Number of log-spaced values of ``w1`` from 2 rad/s to the band the sample rate
        leaves (:func:`~arcosim.identification.excitation.band.sample_band`), a count.

    Returns
    -------
    tuple of (float, str)
        ``(w1, note)``: the best first mode (rad/s) and a line for the report.

    Raises
    ------
    IdentificationError
        When the record shows no motion or no reaction torque.
    """
    check_excited(record)
    short = motor_opening(record, SCAN_SECONDS)
    data = short.tau_hat
    best = (np.inf, 0.0)
    for w1 in np.geomspace(2.0, sample_band(record.h), count):
        cost = float(np.sum((data - predict(short, *chain_at(float(w1)))) ** 2))
        if cost < best[0]:
            best = (cost, float(w1))
    w1 = best[1]
    note = (
        f"scan of the cost over the first clamped mode (2 … {sample_band(record.h):.0f} rad/s) on "
        f"the first {short.duration:g} s: {w1:.4g} rad/s"
    )
    return w1, note


@single_threaded
def uniform_chain(
    record: MotorRecord,
    J: Sequence[float],
    fit_inertia_scale: bool = False,
    k_start: float | None = None,
    zeta_start: float = SCAN_ZETA,
) -> ParameterFit:
    """Fit the paper's uniform chain by output error: one k and one B for every spring.

    Start: ``k_start`` if given, else :func:`scan_first_mode` (the first clamped mode
    of a uniform chain scales as √k); B from ``zeta_start`` on the first mode. The fit
    then runs on longer and longer openings of the record
    (:func:`~arcosim.identification.fit.output_error.continued_fit`).

    Parameters
    ----------
    record : MotorRecord
        The log's reaction-torque record
        (:func:`~arcosim.identification.records.record.motor_record`).
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
    ParameterFit
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
    """Uniform B (N·m·s/rad) giving damping ratio ``zeta`` (dimensionless) on the first
    clamped mode of the uniform chain of stiffness ``k`` (N·m/rad) and inertias ``J``
    (kg·m²)."""
    w1 = float(clamped_frequencies(J, [k] * len(J))[0])
    return 2.0 * zeta * k / w1
