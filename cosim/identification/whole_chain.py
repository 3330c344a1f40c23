"""Identify the whole chain from the motor alone: every J_i, k_i and B_i (offline).

A chain of masses and springs is fixed by its driving-point response (motor angle in,
reaction torque out; :mod:`cosim.chain_modes`), so a motor-side record carries every
inertia, stiffness and damping. The fit is the output-error fit of
:mod:`cosim.output_error` with all 3n parameters free, started from the chain whose
clamped modes and residues the record shows (:mod:`cosim.modal_start`: subspace
identification, no search), on longer and longer openings of the record
(:func:`~cosim.output_error.continued_fit`); given the log's current and encoder
counts, a prediction-error fit from the current to the encoder refines it
(:mod:`cosim.encoder_fit`: the counts bias the output-error B_i).

``masses="auto"`` reads n from the record's modes (the subspace singular values) and
checks it with the Bayesian information criterion of the n − 1, n, n + 1 fits,
computed with the effective number of independent samples (the record over the
Newey–West bandwidth: the residuals are low-passed and coloured, so counting every
sample would favour too many masses).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from arcosim.errors import UserError
from arcosim.identification.encoder_fit import EncoderRecord, refine
from arcosim.identification.modal_start import masses_seen, record_modes, singular_values
from arcosim.identification.output_error import Fit, MotorRecord, check_excited, continued_fit

#: Largest chain ``masses="auto"`` tries.
MAX_AUTO_MASSES = 8


def names(n: int) -> list[str]:
    """Parameter names in fit order: ``J[1]…J[n]``, ``k[1]…k[n]``, ``B[1]…B[n]``."""
    return [f"{p}[{i}]" for p in ("J", "k", "B") for i in range(1, n + 1)]


def split(p: np.ndarray, n: int) -> tuple[list[float], list[float], list[float]]:
    """``(J, k, B)`` from the stacked parameter vector (kg·m², N·m/rad, N·m·s/rad)."""
    return list(p[:n]), list(p[n : 2 * n]), list(p[2 * n :])


def _lower(n: int) -> Callable[[np.ndarray], np.ndarray]:
    """Bounds: inertias and stiffnesses above a thousandth of their start, dampings ≥ 0."""
    return lambda p: np.concatenate([1e-3 * p[: 2 * n], np.zeros(n)])


def fit_chain(record: MotorRecord, n: int) -> Fit:
    """Fit every J_i, k_i, B_i of an n-mass chain to ``record`` (steps in the module doc).

    Returns:
        The fit; ``extra`` holds the modes the start came from (``modes_rad_s``,
        ``damping_ratios``) and the subspace singular values (``singular_values``).

    Raises:
        UserError: for n < 1, or a record that shows no motion, no reaction torque or
            fewer than n modes.
    """
    if n < 1:
        raise UserError(f"the chain needs at least one load mass, got {n}")
    check_excited(record)
    modes = record_modes(record, n)
    J0, k0 = modes.chain()
    zeta = float(np.mean(np.clip(modes.damping, 1e-4, 0.05)))
    B0 = 2.0 * zeta * k0 / modes.frequency[0]
    note = (
        "chain with the record's clamped modes "
        + ", ".join(f"{w:.4g}" for w in modes.frequency)
        + " rad/s (subspace identification) and their residues; then every parameter free"
    )
    start = np.concatenate([J0, k0, B0])
    result = continued_fit(record, names(n), start, lambda p: split(p, n), note, _lower(n))
    result.extra.update(
        modes_rad_s=[float(w) for w in modes.frequency],
        damping_ratios=[float(z) for z in modes.damping],
        singular_values=[float(s) for s in modes.singular_values[: 2 * n + 4]],
    )
    return result


def information_criterion(result: Fit, record: MotorRecord, lag: int | None = None) -> float:
    """BIC with the effective sample count N / lag (lag: the Newey–West bandwidth,
    ``result``'s own unless given; compare fits with one lag)."""
    count = len(record.theta_m)
    effective = max(count / max(lag or result.lag, 1), 2.0)
    rss = result.rms_residual**2
    return effective * math.log(max(rss, 1e-300)) + len(result.values) * math.log(effective)


@dataclass
class Choice:
    """Result of :func:`identify`: the chosen fit and the evidence for n.

    Attributes:
        n: load masses chosen.
        fit: the fit with n masses.
        criterion: BIC per n tried (lower is better).
        rms_residual: rms residual per n tried (N·m).
        refused: per n the record could not support, why.
        seen: with ``"auto"``, the n the subspace singular values show (the largest
            drop comes after the 2n-th; each mode adds a pair).
        singular_values: those singular values, relative to the first.
    """

    n: int
    fit: Fit
    criterion: dict[int, float]
    rms_residual: dict[int, float]
    refused: dict[int, str] = field(default_factory=dict)
    seen: int | None = None
    singular_values: np.ndarray | None = None


def identify(
    record: MotorRecord, masses: int | str, encoder: EncoderRecord | None = None
) -> Choice:
    """Fit an n-mass chain (``masses`` an int) or choose n (``masses="auto"``).

    With ``"auto"``: the record's subspace singular values show n modes
    (:func:`~cosim.modal_start.masses_seen`); chains of n − 1, n and n + 1 masses are
    fitted and the smallest criterion wins (one lag for all, the largest: the residual
    of a good fit is the most correlated). An n the record cannot support (fewer modes
    seen, or a mode that carries no reaction torque) is refused and reported.

    With ``encoder`` (the same log's current and encoder counts), the chosen fit is
    refined by the prediction-error fit (:mod:`cosim.encoder_fit`), which takes the
    counts for what they are; without it the output-error fit is the result.

    Raises:
        UserError: when ``masses`` is neither a positive integer nor ``"auto"``, or the
            record cannot support even one mass.
    """
    if masses != "auto":
        n = _masses(masses)
        result = fit_chain(record, n)
        ic = information_criterion(result, record)
        return Choice(n, _refined(result, record, encoder, n), {n: ic}, {n: result.rms_residual})
    check_excited(record)
    singular = singular_values(record)
    seen = masses_seen(singular, MAX_AUTO_MASSES)
    fits: dict[int, Fit] = {}
    refused: dict[int, str] = {}
    for n in range(max(seen - 1, 1), min(seen + 1, MAX_AUTO_MASSES) + 1):
        try:
            fits[n] = fit_chain(record, n)
        except UserError as error:
            refused[n] = str(error)
    if not fits:
        raise UserError(" ".join(refused.values()))
    lag = max(f.lag for f in fits.values())
    criterion = {n: information_criterion(f, record, lag) for n, f in fits.items()}
    best = min(criterion, key=criterion.__getitem__)
    residual = {n: f.rms_residual for n, f in fits.items()}
    chosen = _refined(fits[best], record, encoder, best)
    return Choice(best, chosen, criterion, residual, refused, seen, singular)


def _refined(result: Fit, record: MotorRecord, encoder: EncoderRecord | None, n: int) -> Fit:
    return result if encoder is None else refine(encoder, record, result, n)


def _masses(masses: int | str) -> int:
    try:
        n = int(masses)
    except ValueError:
        n = 0
    if n < 1 or str(masses).strip() not in (str(n), "auto"):
        raise UserError(f"--masses must be a whole number ≥ 1 or 'auto', got {masses!r}")
    return n
