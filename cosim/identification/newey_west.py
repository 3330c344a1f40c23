"""Standard errors of a fit whose residuals are coloured: Newey–West (offline).

Every fit of the subpackage (the output-error fit, the modal start's residues, the
prediction-error fit) takes its standard errors from a Newey–West (Bartlett) long-run
covariance of the score ``J_t r_t``: the residuals are low-passed by G(s) and coloured
by the chain, so the textbook ``σ² (JᵀJ)⁻¹`` would be far too optimistic.
"""

from __future__ import annotations

import numpy as np

from arcosim.identification.records import MotorRecord


def newey_west_lag(residual: np.ndarray, record: MotorRecord) -> int:
    """Bandwidth (samples) for the long-run covariance of ``residual`` (N·m, shape
    ``(N,)``): :func:`decorrelation_lag` with a floor of five time constants of G(s)
    (``record``'s ``g_dist`` and step)."""
    return decorrelation_lag(residual, int(np.ceil(5.0 / (record.g_dist * record.h))))


def decorrelation_lag(residual: np.ndarray, floor: int) -> int:
    """Three times the lag where the residual's (any unit, shape ``(N,)``)
    autocorrelation first falls below 0.1, at least ``floor`` and at most a tenth of the
    record (samples)."""
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
    the score ``J_t r_t``: the Jacobian ``jac`` (residual units per parameter unit,
    shape ``(N, P)``), the residuals (shape ``(N,)``) and the bandwidth ``lag``
    (samples). Shape ``(P, P)``, in parameter units squared."""
    score = jac * residual[:, None]
    S = score.T @ score
    for lag_k in range(1, lag + 1):
        gamma = score[lag_k:].T @ score[:-lag_k]
        S += (1.0 - lag_k / (lag + 1.0)) * (gamma + gamma.T)
    bread = np.linalg.pinv(jac.T @ jac)
    return bread @ S @ bread
