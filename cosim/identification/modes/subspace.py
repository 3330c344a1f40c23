"""PO-MOESP subspace identification for one input and one output (offline).

Verhaegen, *Automatica* 30, 1994: past inputs and outputs are the instruments; the
extended observability matrix of every model order comes from one LQ decomposition and
one SVD (:func:`observability_matrix`), and each order's state matrix from a shift of it
(:func:`moesp`). The modal start (:mod:`arcosim.identification.modes.detection`) reads the
clamped modes from the poles of those models.
"""

from __future__ import annotations

import numpy as np


def moesp(u: np.ndarray, y: np.ndarray, order: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """PO-MOESP for one input, one output: the eigenvalues of the order-``order``
    state matrix (discrete time, dimensionless, shape ``(order,)``) and the singular
    values of the projected output Hankel matrix (output units, shape ``(rows,)``).

    ``u`` and ``y`` are the input and output samples (any units, shape ``(N,)``),
    ``rows`` the Hankel matrices' block rows (a count); past inputs and outputs are
    the instruments."""
    observability, singular = observability_matrix(u, y, rows)
    A = np.linalg.lstsq(observability[:-1, :order], observability[1:, :order], rcond=None)[0]
    return np.linalg.eigvals(A), singular


def observability_matrix(u: np.ndarray, y: np.ndarray, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """PO-MOESP's extended observability matrix of every order (its first ``order``
    columns are the order-``order`` model's; shape ``(rows, rows)``) and the singular
    values (output units, shape ``(rows,)``), from input ``u`` and output ``y`` (any
    units, shape ``(N,)``) with ``rows`` block rows (a count)."""
    columns = len(u) - 2 * rows + 1
    past_u, future_u = _hankel(u, rows, columns), _hankel(u[rows:], rows, columns)
    past_y, future_y = _hankel(y, rows, columns), _hankel(y[rows:], rows, columns)
    L = np.linalg.qr(np.vstack([future_u, past_u, past_y, future_y]).T, mode="r").T
    projected = L[3 * rows : 4 * rows, rows : 3 * rows]
    left, singular, _ = np.linalg.svd(projected)
    return left * np.sqrt(singular), singular


def _hankel(x: np.ndarray, rows: int, columns: int) -> np.ndarray:
    """The ``(rows, columns)`` Hankel matrix of ``x`` (a view, no copy)."""
    return np.lib.stride_tricks.sliding_window_view(x, columns)[:rows]
