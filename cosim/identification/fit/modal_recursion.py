"""Linear recursions ``x_{j+1} = F x_j + G u_j`` over a whole record, in modal coordinates.

F is diagonalized once and each mode runs as a ``scipy.signal.lfilter`` over the
record: no Python loop per sample. :func:`linear_recursion` forms every state (the
output-error prediction, the Kalman smoother); :func:`output_recursion` only the first
(the Kalman predictor's encoder angle, the prediction-error fit's inner loop).
"""

from __future__ import annotations

import numpy as np
from scipy import signal


def linear_recursion(F: np.ndarray, G: np.ndarray, u: np.ndarray, first: np.ndarray) -> np.ndarray:
    """``x_0 = first``, ``x_{j+1} = F x_j + G u_j``, in modal coordinates with ``lfilter``
    (no Python loop per sample).

    Parameters
    ----------
    F : ndarray
        State matrix (dimensionless, one step), shape ``(S, S)``, diagonalizable.
    G : ndarray
        Input matrix (state units per input unit), shape ``(S, I)``.
    u : ndarray
        Inputs (any units), shape ``(I, M)``.
    first : ndarray
        x_0 (state units), shape ``(S,)``.

    Returns
    -------
    ndarray
        x_0 … x_M as columns (state units), shape ``(S, M + 1)``.
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


def output_recursion(F: np.ndarray, G: np.ndarray, u: np.ndarray) -> np.ndarray:
    """First state of ``x_0 = 0``, ``x_{j+1} = F x_j + G u_j`` (shape (M + 1,)), in modal
    coordinates, only the first state formed: a real eigenvalue is one first-order
    ``lfilter``, a conjugate pair one real second-order ``lfilter`` (its inputs combined
    beforehand), so the cost is a few real filters over the record."""
    lam, V = np.linalg.eig(F)
    weights = V[0, :, None] * np.linalg.solve(V, np.asarray(G, dtype=complex))  # (S, I)
    out = np.zeros(u.shape[1] + 1)
    done = np.zeros(len(lam), dtype=bool)
    for j, root in enumerate(lam):
        if done[j]:
            continue
        done[j] = True
        if abs(root.imag) <= 1e-12 * max(abs(root), 1e-300):
            out[1:] += signal.lfilter([1.0], [1.0, -root.real], weights[j].real @ u)
            continue
        partner = np.flatnonzero(~done & (np.abs(lam - np.conj(root)) <= 1e-9 * abs(root)))
        if partner.size:
            done[partner[0]] = True
        # c/(1 − λz⁻¹) + c̄/(1 − λ̄z⁻¹) = (2 Re c − 2 Re(c λ̄) z⁻¹) / (1 − 2 Re λ z⁻¹ + |λ|² z⁻²)
        b0 = 2.0 * weights[j].real @ u
        b1 = -2.0 * (weights[j] * np.conj(root)).real @ u
        v = b0.copy()
        v[1:] += b1[:-1]
        out[1:] += signal.lfilter([1.0], [1.0, -2.0 * root.real, abs(root) ** 2], v)
    return out
