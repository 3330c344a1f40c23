"""Identify the whole chain from the motor alone: every J_i, k_i and B_i (offline).

A chain of masses and springs is fixed by its driving-point response (motor angle in,
reaction torque out; a ladder network is fixed by its continued-fraction expansion),
so a motor-side record carries every inertia, stiffness and damping. The fit is the
output-error fit of :mod:`cosim.output_error` with all 3n parameters free, reached in
three steps, each starting the next:

1. a scan over the first clamped mode of a uniform chain of unit inertias, with the
   least-squares common scale (a common scale on J, k and B scales the torque), on
   the record's first :data:`~cosim.output_error.SCAN_SECONDS`;
2. the uniform chain (one J, one k, one B), fitted on longer and longer openings of
   the record (:func:`~cosim.output_error.continued_fit`);
3. every J_i, k_i, B_i, again on longer and longer openings.

``masses="auto"`` fits n = 1, 2, … and keeps the n with the smallest Bayesian
information criterion, computed with the effective number of independent samples
(the record over the Newey–West bandwidth: the residuals are low-passed and coloured,
so counting every sample would favour too many masses).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from cosim.errors import UserError
from cosim.output_error import (
    SCAN_ZETA,
    Fit,
    MotorRecord,
    clamped_frequencies,
    continued_fit,
    scan_first_mode,
)

#: Largest chain ``masses="auto"`` tries.
MAX_AUTO_MASSES = 6

Chain = tuple[list[float], list[float], list[float]]


def names(n: int) -> list[str]:
    """Parameter names in fit order: ``J[1]…J[n]``, ``k[1]…k[n]``, ``B[1]…B[n]``."""
    return [f"{p}[{i}]" for p in ("J", "k", "B") for i in range(1, n + 1)]


def split(p: np.ndarray, n: int) -> Chain:
    """``(J, k, B)`` from the stacked parameter vector (kg·m², N·m/rad, N·m·s/rad)."""
    return list(p[:n]), list(p[n : 2 * n]), list(p[2 * n :])


def _lower(n: int) -> Callable[[np.ndarray], np.ndarray]:
    """Bounds: inertias and stiffnesses above a thousandth of their start, dampings ≥ 0."""
    return lambda p: np.concatenate([1e-3 * p[: 2 * n], np.zeros(n)])


def fit_chain(record: MotorRecord, n: int) -> Fit:
    """Fit every J_i, k_i, B_i of an n-mass chain to ``record`` (steps in the module doc).

    Returns:
        The fit; ``extra["uniform"]`` holds the uniform chain of step 2.

    Raises:
        UserError: for n < 1 or a record that shows no motion or no reaction torque.
    """
    if n < 1:
        raise UserError(f"the chain needs at least one load mass, got {n}")
    unit = float(clamped_frequencies([1.0] * n, [1.0] * n)[0])

    def unit_chain(w1: float) -> Chain:
        k = (w1 / unit) ** 2
        return [1.0] * n, [k] * n, [2.0 * SCAN_ZETA * k / w1] * n

    w1, scale, note = scan_first_mode(record, unit_chain, free_scale=True)
    J0, k0, B0 = (scale * v[0] for v in unit_chain(w1))

    def uniform(p: np.ndarray) -> Chain:
        return [p[0]] * n, [p[1]] * n, [p[2]] * n

    common = continued_fit(
        record, ["J", "k", "B"], np.array([J0, k0, B0]), uniform, note, _lower(1)
    )
    J1, k1, B1 = common.values
    start = np.array([J1] * n + [k1] * n + [max(B1, 1e-3 * B0)] * n)
    note += (
        f"; uniform chain J = {J1:.4g} kg.m2, k = {k1:.4g} N.m/rad, B = {B1:.3g} N.m.s/rad; "
        "then every parameter free"
    )
    result = continued_fit(record, names(n), start, lambda p: split(p, n), note, _lower(n))
    result.extra["uniform"] = common.as_dict()
    return result


def information_criterion(result: Fit, record: MotorRecord) -> float:
    """BIC with the effective sample count N / lag (lag: Newey–West bandwidth)."""
    count = len(record.theta_m)
    effective = max(count / max(result.lag, 1), 2.0)
    rss = result.rms_residual**2
    return effective * math.log(max(rss, 1e-300)) + len(result.values) * math.log(effective)


@dataclass
class Choice:
    """Result of :func:`identify`: the chosen fit and the evidence for n."""

    n: int
    fit: Fit
    criterion: dict[int, float]
    rms_residual: dict[int, float]


def identify(record: MotorRecord, masses: int | str) -> Choice:
    """Fit an n-mass chain (``masses`` an int) or choose n (``masses="auto"``).

    With ``"auto"``, n = 1, 2, … up to :data:`MAX_AUTO_MASSES`, stopping once the
    criterion has risen twice in a row; the smallest criterion wins.
    """
    if masses != "auto":
        n = int(masses)
        result = fit_chain(record, n)
        ic = information_criterion(result, record)
        return Choice(n, result, {n: ic}, {n: result.rms_residual})
    fits: dict[int, Fit] = {}
    criterion: dict[int, float] = {}
    for n in range(1, MAX_AUTO_MASSES + 1):
        fits[n] = fit_chain(record, n)
        criterion[n] = information_criterion(fits[n], record)
        if n >= 3 and criterion[n] > criterion[n - 1] > criterion[n - 2]:
            break
    best = min(criterion, key=criterion.__getitem__)
    return Choice(best, fits[best], criterion, {n: f.rms_residual for n, f in fits.items()})
