"""Start values for the whole-chain fit from the record's own modes (offline).

The output-error cost of a lightly damped chain has local minima spaced by about
π / T in each mode's frequency (T the record length), so the fit needs every clamped
frequency to a fraction of a rad/s before it starts. Three linear steps get there
with no search:

1. subspace identification (PO-MOESP; Verhaegen, *Automatica* 30, 1994) of the
   response from the motor angle, passed through the DOB's G(s), to τ̂_reac: its poles
   are the clamped modes p_i and their damping ratios;
2. the residues r_i of ``τ/θ_m = k_1 − Σ r_i / (s² + 2ζ_i p_i s + p_i²)`` by
   non-negative least squares on the record, the p_i held;
3. the chain (J_i, k_i) with those modes (:func:`cosim.chain_modes.chain_from_modes`).

What the record must have (measured on the accuracy benchmark's chains, README):
a broadband excitation with many lines (a multi-sine of 40 log-spaced lines 3–150
rad/s rings all five modes of the five-mass chain; 11 lines do not, the subspace
then takes excitation lines for modes) and modes below 3 g_dist, where G(s) still
passes a third of the torque.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, signal

from arcosim.errors import UserError
from arcosim.identification.chain_modes import chain_from_modes
from arcosim.identification.output_error import MotorRecord

#: Block rows of the subspace method's Hankel matrices (decimated samples).
ROWS = 60
#: Highest clamped frequency sought, in units of g_dist (rad/s).
BAND_PER_G = 3.0
#: Damping ratios a clamped mode may show in the subspace model.
DAMPING_RANGE = (-0.05, 0.3)


@dataclass(frozen=True)
class Modes:
    """Clamped modes seen in a record.

    Attributes:
        frequency: undamped frequencies p_i (rad/s), ascending, shape (n,).
        damping: damping ratios ζ_i, shape (n,).
        residue: residues r_i (N·m/rad·s⁻²), shape (n,).
        singular_values: of the subspace step, relative to the first (evidence for n).
        band: highest frequency sought (rad/s).
    """

    frequency: np.ndarray
    damping: np.ndarray
    residue: np.ndarray
    singular_values: np.ndarray
    band: float

    def chain(self) -> tuple[np.ndarray, np.ndarray]:
        """``(J, k)`` of the chain with these modes (kg·m², N·m/rad)."""
        return chain_from_modes(self.frequency, self.residue)


def record_modes(record: MotorRecord, n: int) -> Modes:
    """The n clamped modes of the chain in ``record`` and their residues.

    Raises:
        UserError: when the record is too short, or shows fewer than n modes.
    """
    band = _band(record)
    u, y, step = _decimated(record, band)
    rows = max(2 * n + 4, min(ROWS, len(u) // 8))
    if len(u) < 8 * (2 * n + 4):
        raise UserError(
            f"the record ({record.duration:g} s) is too short to find {n} modes below "
            f"{band:.0f} rad/s; record at least {8 * (2 * n + 4) * step:.1f} s (20 s advised)"
        )
    frequency, damping, singular = _modes(u, y, n, rows, step, band)
    if len(frequency) < n:
        found = ", ".join(f"{w:.1f}" for w in frequency) or "none"
        raise UserError(
            f"the record shows {len(frequency)} lightly damped mode(s) below {band:.0f} rad/s "
            f"({found} rad/s), {chain_of(n)} has {n}: excite every mode (a multi-sine "
            "with many lines across the band, `arcosim simulate --scenario identification`) "
            "or fit fewer masses"
        )
    residue = residues(record, frequency, damping)
    if np.any(residue <= 0.0):
        missing = ", ".join(f"{w:.1f}" for w in frequency[residue <= 0.0])
        raise UserError(
            f"the mode(s) at {missing} rad/s carry no reaction torque when the record is "
            f"read as {chain_of(n)}: try another number of masses (--masses auto)"
        )
    return Modes(frequency, damping, residue, singular / singular[0], band)


def singular_values(record: MotorRecord) -> np.ndarray:
    """Singular values of the subspace step (relative to the first, shape (rows,)):
    each lightly damped mode the record shows adds a pair above the noise floor."""
    band = _band(record)
    u, y, _ = _decimated(record, band)
    rows = min(ROWS, len(u) // 8)
    if rows < 4:
        raise UserError(f"the record ({record.duration:g} s) is too short to show its modes")
    singular = moesp(u, y, 2, rows)[1]
    return singular / singular[0]


def masses_seen(singular: np.ndarray, largest: int) -> int:
    """The n ≤ ``largest`` after whose 2n-th singular value the largest drop comes."""
    pairs = range(1, min(largest, (len(singular) - 1) // 2) + 1)
    return max(pairs, key=lambda n: singular[2 * n - 1] / max(singular[2 * n], 1e-300))


def _band(record: MotorRecord) -> float:
    """Highest clamped frequency sought (rad/s): :data:`BAND_PER_G` · g_dist, at most
    0.3/h (the band the sample rate leaves)."""
    return min(BAND_PER_G * record.g_dist, 0.3 / record.h)


def chain_of(n: int) -> str:
    """``"a chain of 1 mass"``, ``"a chain of 3 masses"``."""
    return f"a chain of {n} mass{'es' if n != 1 else ''}"


def _decimated(record: MotorRecord, band: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Motor angle through G(s) and τ̂_reac, both low-passed (zero phase) and decimated
    so that the Nyquist frequency is about ``band``; and the new step (s)."""
    a = np.exp(-record.g_dist * record.h)
    u = signal.lfilter([1.0 - a], [1.0, -a], record.theta_m - record.theta_m[0])
    y = record.tau_hat
    factor = max(1, int(np.pi / (band * record.h)))
    if factor > 1:
        b, a_ = signal.butter(4, 0.8 / factor)
        u, y = (signal.filtfilt(b, a_, x)[::factor] for x in (u, y))
    return u, y, factor * record.h


def _modes(
    u: np.ndarray, y: np.ndarray, n: int, rows: int, step: float, band: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lightly damped complex poles below ``band`` of a subspace model of order 2n
    (then 2n + 2, 2n + 4 if spurious poles took some of the order): the n least damped,
    by frequency. Returns (frequency, damping, singular values)."""
    best: tuple[np.ndarray, np.ndarray] = (np.empty(0), np.empty(0))
    singular = np.empty(0)
    for order in (2 * n, 2 * n + 2, 2 * n + 4):
        eigenvalues, sv = moesp(u, y, order, rows)
        if order == 2 * n:
            singular = sv
        poles = np.log(eigenvalues[eigenvalues.imag > 0].astype(complex)) / step
        frequency = np.abs(poles)
        damping = -poles.real / frequency
        keep = (frequency < band) & (damping > DAMPING_RANGE[0]) & (damping < DAMPING_RANGE[1])
        frequency, damping = frequency[keep], damping[keep]
        chosen = np.argsort(np.abs(damping))[:n]
        chosen = chosen[np.argsort(frequency[chosen])]
        if len(chosen) > len(best[0]):
            best = (frequency[chosen], damping[chosen])
        if len(chosen) == n:
            break
    return best[0], best[1], singular


def moesp(u: np.ndarray, y: np.ndarray, order: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """PO-MOESP for one input, one output: the eigenvalues of the order-``order``
    state matrix (discrete time) and the singular values of the projected output
    Hankel matrix (shape (rows,)); past inputs and outputs are the instruments."""
    columns = len(u) - 2 * rows + 1
    past_u, future_u = _hankel(u, rows, columns), _hankel(u[rows:], rows, columns)
    past_y, future_y = _hankel(y, rows, columns), _hankel(y[rows:], rows, columns)
    L = np.linalg.qr(np.vstack([future_u, past_u, past_y, future_y]).T, mode="r").T
    projected = L[3 * rows : 4 * rows, rows : 3 * rows]
    left, singular, _ = np.linalg.svd(projected)
    observability = left[:, :order] * np.sqrt(singular[:order])
    A = np.linalg.lstsq(observability[:-1], observability[1:], rcond=None)[0]
    return np.linalg.eigvals(A), singular


def _hankel(x: np.ndarray, rows: int, columns: int) -> np.ndarray:
    return np.lib.stride_tricks.sliding_window_view(x, columns)[:rows]


def residues(record: MotorRecord, frequency: np.ndarray, damping: np.ndarray) -> np.ndarray:
    """Residues r_i ≥ 0 of the modal model on the record, the modes held (shape (n,)).

    Each regressor is the motor angle through ``1/p² − 1/(s² + 2ζps + p²)`` and G(s)
    (so the static torque k_1 − Σ r_i / p_i² is zero, as it is for a free load chain);
    0 means the mode does not explain the record.
    """
    h = record.h
    u = record.theta_m - record.theta_m[0]
    a = np.exp(-record.g_dist * h)
    columns = []
    for p, zeta in zip(frequency, np.clip(damping, 1e-4, None)):
        numerator = [1.0, 2.0 * zeta * p, 0.0]
        denominator = [p**2, 2.0 * zeta * p**3, p**4]
        b, a_, _ = signal.cont2discrete((numerator, denominator), h, method="bilinear")
        columns.append(signal.lfilter([1.0 - a], [1.0, -a], signal.lfilter(b.ravel(), a_, u)))
    regressors = np.array(columns).T
    norms = np.linalg.norm(regressors, axis=0)
    norms[norms == 0.0] = 1.0
    r, _ = optimize.nnls(regressors / norms, record.tau_hat)
    return r / norms
